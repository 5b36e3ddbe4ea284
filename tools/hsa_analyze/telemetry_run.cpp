#include "tools/hsa_analyze/telemetry_run.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hsa::analyze {
namespace {

using control::identification::ClosedLoopRun;
using control::identification::RunRefused;

// status_t.STATE_ENABLED (msgs/status_t.lcm).
constexpr int kStateEnabled = 2;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (!cells.empty() && !cells.back().empty() && cells.back().back() == '\r') cells.back().pop_back();
  return cells;
}

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
  const std::vector<std::string> header = split(line);
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
    const std::vector<std::string> cells = split(line);
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
  const double seq_step = seq[1] - seq[0];
  const double period_us = (utime.back() - utime.front()) / static_cast<double>(utime.size() - 1);
  for (std::size_t k = 1; k < utime.size(); ++k) {
    if (seq[k] - seq[k - 1] != seq_step || std::abs(utime[k] - utime[k - 1] - period_us) > 0.1 * period_us)
      throw RunRefused("samples " + std::to_string(k) + " and " + std::to_string(k + 1) +
                       " are not one loop period apart (dropped or decimated telemetry): record at the cylinder "
                       "loop's rate (hsad's telemetry at its default 1 kHz)");
  }
  run.period_s = period_us * 1e-6;
  return run;
}

}  // namespace hsa::analyze
