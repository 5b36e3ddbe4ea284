// `hsactl capture export`: a capture as CSV, one column per signal in the file's (the recorder's)
// order, one row per sample, and a last column `trigger`, 1 on the trigger's row and 0 elsewhere.
// The header names each column with its unit in brackets when the file gives one
// ("position_m [m]"). Values are written in the shortest form that reads back as the same double
// (whole numbers without an exponent).
#pragma once

#include <ostream>
#include <string>

#include "tools/hsactl/capture_reader.hpp"

namespace hsa::ctl {

void write_capture_csv(std::ostream& out, const Capture& capture);

// Reads `mat` and writes `csv` (through csv.part, renamed when complete). Refuses, changing nothing,
// an existing `csv` unless `overwrite`, and a file that is no capture: std::runtime_error
// (CaptureFileError for the latter) naming the file.
void export_capture_csv(const std::string& mat, const std::string& csv, bool overwrite);

}  // namespace hsa::ctl
