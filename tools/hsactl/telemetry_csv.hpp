// Telemetry as CSV, for `hsactl record` and for logs written by lcm-logger (`hsactl log2csv`).
// Columns are SI units, as in the messages, so a spreadsheet or a plot script needs no guessing.
#pragma once

#include <ostream>

#include "hsa/telemetry_t.hpp"

namespace hsa::ctl {

void write_telemetry_csv_header(std::ostream& out);
void write_telemetry_csv_row(std::ostream& out, const hsa::telemetry_t& t);

}  // namespace hsa::ctl
