// One line of the plain CSV hsactl record and hsa-analyze write (no quoting: every cell is a
// number or a bare word), split at its commas; a trailing '\r' from a file edited on Windows is
// dropped. Shared by the readers of recorded runs (telemetry_run, valve_record).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace hsa::analyze {

inline std::vector<std::string> csv_cells(const std::string& line) {
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

}  // namespace hsa::analyze
