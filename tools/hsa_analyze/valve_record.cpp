#include "tools/hsa_analyze/valve_record.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "control/identification/identify_run.hpp"
#include "tools/hsa_analyze/csv_cells.hpp"

namespace hsa::analyze {
namespace {

using control::identification::RunRefused;

std::string at(std::size_t line, const std::string& column) {
  return "line " + std::to_string(line) + ", column " + column + ": ";
}

}  // namespace

control::identification::ValveRecord read_valve_record(std::istream& csv) {
  std::string line;
  if (!std::getline(csv, line))
    throw RunRefused("the file is empty: expected the CSV of `hsa-analyze experiment valve-excite --csv`");
  const std::vector<std::string> header = csv_cells(line);
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < header.size(); ++k) index[header[k]] = k;
  const std::string needed[] = {"t_s", "command_a", "current_a", "spool_m"};
  for (const std::string& name : needed)
    if (!index.count(name))
      throw RunRefused("line 1: the CSV has no column '" + name +
                       "': expected t_s, command_a, current_a and spool_m (hsa-analyze experiment valve-excite)");

  control::identification::ValveRecord r;
  std::vector<double> time;
  std::vector<double>* columns[] = {&time, &r.command_a, &r.current_a, &r.spool_m};
  std::size_t number = 1;
  while (std::getline(csv, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> cells = csv_cells(line);
    for (std::size_t c = 0; c < 4; ++c) {
      const std::size_t i = index[needed[c]];
      if (i >= cells.size())
        throw RunRefused(at(number, needed[c]) + "missing: the row has " + std::to_string(cells.size()) + " cells");
      const std::string& cell = cells[i];
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      if (ec != std::errc{} || ptr != cell.data() + cell.size() || !std::isfinite(v))
        throw RunRefused(at(number, needed[c]) + "'" + cell + "' is not a finite number");
      columns[c]->push_back(v);
    }
  }
  if (time.size() < 2) throw RunRefused("the CSV has fewer than two rows of samples");
  std::vector<double> steps(time.size() - 1);
  for (std::size_t k = 0; k + 1 < time.size(); ++k) steps[k] = time[k + 1] - time[k];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  r.period_s = sorted[sorted.size() / 2];
  if (!(r.period_s > 0.0)) throw RunRefused("column t_s: the times do not increase");
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (std::abs(steps[k] - r.period_s) > 0.01 * r.period_s)
      throw RunRefused(at(k + 3, "t_s") + "the time steps by " + std::to_string(steps[k]) + " s, not the period " +
                       std::to_string(r.period_s) + " s: the fit needs one row per valve period, no gaps");
  return r;
}

}  // namespace hsa::analyze
