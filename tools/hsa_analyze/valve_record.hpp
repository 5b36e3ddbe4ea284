// Reads a valve identification record (the CSV `hsa-analyze experiment valve-excite --csv` writes,
// columns in tools/hsa_analyze/valve_excitation.hpp) into the samples
// control/identification/valve_fit.hpp fits: columns by name, t_s, command_a, current_a and
// spool_m required, any others ignored; one row per valve period.
//
// Refused (control::identification::RunRefused, naming the line and column): an empty file, a
// missing column, a row with too few cells, a cell that is not a finite number, fewer than two
// rows, times that do not step by one period (the median step) within 1 %.
#pragma once

#include <istream>

#include "control/identification/valve_fit.hpp"

namespace hsa::analyze {

[[nodiscard]] control::identification::ValveRecord read_valve_record(std::istream& csv);

}  // namespace hsa::analyze
