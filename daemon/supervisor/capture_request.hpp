// An operator's request to an axis's flight recorder (command_t.CAPTURE, `hsactl capture`): take a
// capture now, arm a condition on one of the recorder row's signals, or disarm it
// (docs/flight-recorder.md, Triggers). Plain data, as every command crossing the axis's port is.
//
// The LCM bridge's validation fills what the wire says (finite numbers, a known action); the
// operator thread resolves the rest against the axis's ring (daemon/hsad/capture_gate.hpp): the
// signal's index and the lengths in rows, refused there with a reason when they do not fit. The RT
// thread (AxisRecorder::apply) only stores the result.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hsa::daemon {

enum class CaptureAction : std::uint8_t { now, arm, disarm };
// Which way the signal must cross the level: from at-or-below to above, or from at-or-above to below.
enum class Crossing : std::uint8_t { above, below };

// Room for a recorder signal's name (recorder_row.hpp: the longest is 17 characters) and its NUL.
inline constexpr std::size_t kCaptureSignalSize = 32;
// "Use the ring's default" for a length given in rows (CaptureTrigger, CaptureRequest).
inline constexpr std::uint32_t kRingDefaultRows = 0xFFFFFFFFu;

struct CaptureRequest {
  CaptureAction action = CaptureAction::now;
  // History before the trigger row and rows after it, s; negative: the ring's defaults (the whole
  // ring before, [axes.recorder] post_trigger_s after).
  double pre_s = -1.0;
  double post_s = -1.0;
  // arm: the signal (its name in a capture file, NUL-terminated), the crossing and its level, and
  // whether it fires once (then disarms) or at every crossing.
  char signal[kCaptureSignalSize] = {};
  Crossing crossing = Crossing::above;
  double level = 0.0;
  bool repeat = false;
  // Resolved on the operator thread (capture_gate): what the RT thread uses.
  std::int16_t signal_index = -1;
  std::uint32_t pre_rows = kRingDefaultRows;
  std::uint32_t post_rows = kRingDefaultRows;
};

}  // namespace hsa::daemon
