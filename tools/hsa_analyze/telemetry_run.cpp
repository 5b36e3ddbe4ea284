#include "tools/hsa_analyze/telemetry_run.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tools/hsa_analyze/csv_cells.hpp"

namespace hsa::analyze {
namespace {

using control::identification::ClosedLoopRun;
using control::identification::RunRefused;

// status_t.STATE_ENABLED (msgs/status_t.lcm).
constexpr int kStateEnabled = 2;

double number(const std::string& cell, std::size_t row, const std::string& column) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc{} || ptr != cell.data() + cell.size())
    throw RunRefused("row " + std::to_string(row) + ", column " + column + ": '" + cell + "' is not a number");
  return v;
}

}  // namespace

ClosedLoopRun read_telemetry_run(std::istream& csv) {
  std::string line;
  if (!std::getline(csv, line)) throw RunRefused("the file is empty: expected the CSV of `hsactl record`");
  const std::vector<std::string> header = csv_cells(line);
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < header.size(); ++k) index[header[k]] = k;
  const char* needed[] = {"utime_us",      "seq",           "state",         "valve_enabled", "setpoint_m",
                          "position_m",    "valve_opening", "pressure_a_pa", "pressure_b_pa"};
  for (const char* name : needed)
    if (!index.count(name))
      throw RunRefused(std::string("the CSV has no column '") + name + "': expected the CSV of `hsactl record`");

  ClosedLoopRun run;
  std::vector<double> utime, seq;
  std::size_t row = 1;
  while (std::getline(csv, line)) {
    ++row;
    if (line.empty()) continue;
    const std::vector<std::string> cells = csv_cells(line);
    if (cells.size() != header.size())
      throw RunRefused("row " + std::to_string(row) + " has " + std::to_string(cells.size()) + " cells, the header " +
                       std::to_string(header.size()));
    const auto get = [&](const char* name) { return number(cells[index.at(name)], row, name); };
    if (get("state") != kStateEnabled || get("valve_enabled") != 1.0)
      throw RunRefused("row " + std::to_string(row) +
                       ": the axis was not enabled with its valve on (state " + cells[index.at("state")] +
                       "): identify a run in which the loop stayed closed, without faults");
    utime.push_back(get("utime_us"));
    seq.push_back(get("seq"));
    run.setpoint_m.push_back(get("setpoint_m"));
    run.position_m.push_back(get("position_m"));
    run.opening.push_back(get("valve_opening"));
    run.pressure_a_pa.push_back(get("pressure_a_pa"));
    run.pressure_b_pa.push_back(get("pressure_b_pa"));
  }
  if (utime.size() < 2) throw RunRefused("the run has fewer than 2 samples");
  // The schedule is in `seq` (base ticks), the wake time in `utime_us` (which carries the cycle's
  // lateness): the nominal step between samples is the median seq step (steps a tick long or
  // short come in pairs around it).
  std::vector<double> steps;
  for (std::size_t k = 1; k < seq.size(); ++k) steps.push_back(seq[k] - seq[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  const double seq_step = steps[steps.size() / 2];
  if (!(seq_step > 0.0)) throw RunRefused("the samples' seq does not advance");
  for (std::size_t k = 1; k < seq.size(); ++k) {
    const double step = seq[k] - seq[k - 1];
    if (step <= 0.0 || step > 5.0 * seq_step)
      throw RunRefused("samples " + std::to_string(k) + " and " + std::to_string(k + 1) + " are " +
                       std::to_string(step / seq_step) +
                       " loop periods apart (dropped or decimated telemetry): record at the cylinder loop's rate "
                       "(hsad's telemetry at its default 1 kHz)");
  }
  // A host that misses base periods moves a cylinder-loop sample a base tick or two off its grid
  // (seq steps of 9 and 11 instead of 10), and now and then a telemetry sample is lost on the way.
  // The fits assume one sample per loop period, so the run is taken on the grid, each point from
  // the sample nearest to it in ticks (at most two and a half periods away: a gap of more than
  // four missing samples is refused above, and so is a run with more than 5 % of its points so
  // taken). A missing sample is most often a period the loop itself did not run: a VM that
  // stops the RT thread for a few milliseconds. Every row keeps its own setpoint, position, opening and
  // pressures together, and no value is interpolated; the points so taken are counted.
  const double tick_us = (utime.back() - utime.front()) / (seq.back() - seq.front());
  const auto points = static_cast<std::size_t>(std::floor((seq.back() - seq.front()) / seq_step)) + 1;
  ClosedLoopRun grid;
  std::size_t k = 0;
  for (std::size_t j = 0; j < points; ++j) {
    const double target = seq.front() + static_cast<double>(j) * seq_step;
    while (k + 1 < seq.size() && std::abs(seq[k + 1] - target) <= std::abs(seq[k] - target)) ++k;
    if (seq[k] != target) ++grid.off_grid_samples;
    grid.setpoint_m.push_back(run.setpoint_m[k]);
    grid.position_m.push_back(run.position_m[k]);
    grid.opening.push_back(run.opening[k]);
    grid.pressure_a_pa.push_back(run.pressure_a_pa[k]);
    grid.pressure_b_pa.push_back(run.pressure_b_pa[k]);
  }
  grid.period_s = seq_step * tick_us * 1e-6;
  if (grid.off_grid_samples > points / 20) {
    throw RunRefused(std::to_string(grid.off_grid_samples) + " of " + std::to_string(points) +
                     " loop periods have no sample of their own (more than 5 %): the host missed too many of the "
                     "loop's periods; record on a quieter host, or check hsad's overruns in its status");
  }
  return grid;
}

}  // namespace hsa::analyze
