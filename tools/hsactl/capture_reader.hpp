// Reads a flight recorder capture (docs/flight-recorder.md, daemon/recorder/capture_file.hpp) with
// libmatio, without anything of hsad: what `hsactl captures`, `capture export` and `scope` show.
//
// A capture is a MAT-file (level 5) holding `trigger_index` (1-based) and one double column vector
// per signal, all of one length; the signals are taken in the file's own order (the recorder's
// column order), so a file written by another hsad version with more or fewer columns reads too.
// Strings (UTF-16 in the file) come back as UTF-8; `units` ("name: unit" lines) names each
// signal's unit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace hsa::ctl {

// A file that is not a MAT-file, or not a capture; what() names the file and what is missing.
class CaptureFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CaptureSignal {
  std::string name;
  std::string unit;  // from the file's `units`; "" when it has none for this signal
  std::vector<double> values;  // empty when only the header was read
};

struct Capture {
  std::string axis, trigger, trigger_state, fault, reason, gains, law;
  std::size_t rows = 0;
  std::size_t trigger_index = 0;  // 1-based, as in the file
  double trigger_tick = 0.0;
  double sample_rate_hz = 0.0;  // 0 when the file has none
  double merged_triggers = 0.0;
  std::vector<CaptureSignal> signals;  // in the file's order

  // The time the rows span, s: last t − first t + one base period (base ticks the executive skipped,
  // its overruns, included); rows / sample_rate_hz without t; 0 without a rate.
  double duration_s = 0.0;
  // The signal called `name`, or nullptr.
  [[nodiscard]] const CaptureSignal* signal(const std::string& name) const;
};

// Reads the strings, the scalars and each signal's name and unit, not the rows' values (`rows`
// from the vectors' dimensions). Throws CaptureFileError.
Capture read_capture_header(const std::string& path);
// The same and every signal's values.
Capture read_capture(const std::string& path);

}  // namespace hsa::ctl
