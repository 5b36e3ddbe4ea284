// One capture as a MAT-file (level 5, zlib-compressed), written with libmatio: MATLAB, Octave and
// scipy.io.loadmat read it as it is, with nothing of hsa installed (docs/flight-recorder.md).
//
// The file holds one column vector (double) per signal of HSA_RECORDER_SIGNALS, plus `t` (s from
// the trigger row) and `utime_us` (CLOCK_MONOTONIC µs, as telemetry_t.utime); the trigger as
// `trigger_index` (1-based, MATLAB's convention: row trigger_index of every vector is the trigger's
// cycle) and `trigger_tick`; `sample_rate_hz`, `merged_triggers`; and as strings the axis, the
// trigger kind (fault, operator, condition), a condition's description, the state entered (or the
// state then), the fault (its identifier and sentence), the gains, the law's parameters, the
// column units and the daemon's configuration text.
#pragma once

#include <cstdint>
#include <string>

#include "daemon/recorder/capture_ring.hpp"

namespace hsa::daemon {

// What a file says beside the rows; fixed when hsad starts.
struct CaptureContext {
  std::string axis;
  std::string configuration;  // the configuration file's text
  std::string law;            // ControlLaw::describe()
  double sample_rate_hz = 0.0;
  std::int64_t epoch_ns = 0;  // CLOCK_MONOTONIC of the daemon's t_ns = 0
};

// The file's `trigger`: "fault", "operator" or "condition".
std::string capture_trigger_word(const CaptureTrigger& why);
// A condition trigger's description, "following_error_m above 0.001" (the file's `condition`).
std::string capture_condition(const CaptureTrigger& why);
// The sentence a file's `reason` holds: describe(fault), the state entered (an e-stop), "operator
// request", or "condition " and the condition's description.
std::string capture_reason(const CaptureTrigger& why);
// What a file name carries as its reason: the fault's identifier, "estop", "fault", "operator",
// or the condition's description (capture_file_name reduces it to "following_error_m_above_0_001").
std::string capture_reason_word(const CaptureTrigger& why);

// Writes `capture` to `path` (through `path`.part, renamed when complete, so a reader never sees a
// partial file). Returns the file's size in bytes. Throws std::runtime_error naming the file and
// the reason, with no file left behind.
std::uint64_t write_capture_mat(const std::string& path, const Capture& capture, const CaptureContext& context);

}  // namespace hsa::daemon
