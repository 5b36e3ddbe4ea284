// Reads a closed-loop identification run from the CSV that `hsactl record` writes
// (tools/hsactl/telemetry_csv.hpp: one row per telemetry sample, columns by name, SI units) into
// the samples control/identification/identify_run.hpp fits.
//
// Refused (control::identification::RunRefused, with what to change):
// - a missing column, or a row that does not parse;
// - a row whose axis was not ENABLED with its valve on (a fault, an e-stop, a disabled axis):
//   the loop was not closed as the model assumes;
// - samples more than five loop periods apart in `seq` (decimated telemetry, or more than four
//   samples lost): `hsactl record` must run at the cylinder loop's rate (1 kHz);
// - more than 5 % of the loop's periods without a sample of their own (below).
// A sample a base tick or two off the loop's grid (the host missed a base period, so the loop ran
// a tick late or early), or a lost one, is taken from the row nearest to that grid point, and
// counted in ClosedLoopRun::off_grid_samples, which `identify` prints.
#pragma once

#include <istream>

#include "control/identification/identify_run.hpp"

namespace hsa::analyze {

[[nodiscard]] control::identification::ClosedLoopRun read_telemetry_run(std::istream& csv);

}  // namespace hsa::analyze
