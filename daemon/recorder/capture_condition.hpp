// A condition trigger of the flight recorder, armed by an operator (`hsactl capture AXIS --when
// SIGNAL --above X`): it fires on the row where one of the recorder row's signals crosses a level.
//
// Crossing, not level: `above X` fires on a row whose value is > X when the row before it was not
// (<= X, or NaN), `below X` on a row < X after one that was not. The first row seen after arming only
// sets that reference, so arming while the signal is already beyond the level waits for it to come
// back and cross again; a NaN row is never beyond. Single-shot disarms itself when it fires; repeat
// stays armed and fires at every crossing (a crossing while the capture it started still collects
// its post-trigger rows falls into that capture: CaptureRing counts it as merged).
//
// RT thread: evaluate() is a call through the signal's function pointer (recorder_signals.hpp,
// resolved off the RT thread), a comparison and a few stores.
#pragma once

#include <cstdint>
#include <string>

#include "daemon/recorder/recorder_row.hpp"
#include "daemon/supervisor/capture_request.hpp"

namespace hsa::daemon {

struct ConditionSpec {
  int signal = -1;  // index into kRecorderSignals
  Crossing crossing = Crossing::above;
  double level = 0.0;
  bool repeat = false;
};

class CaptureCondition {
 public:
  // `spec.signal` must index kRecorderSignals (the operator thread checked it); the reference row
  // is forgotten.
  void arm(const ConditionSpec& spec) noexcept;
  void disarm() noexcept { armed_ = false; }
  // Whether `row` is a crossing of the armed condition; a single-shot one disarms itself here.
  [[nodiscard]] bool evaluate(const RecorderRow& row) noexcept;

  [[nodiscard]] bool armed() const noexcept { return armed_; }
  [[nodiscard]] const ConditionSpec& spec() const noexcept { return spec_; }

 private:
  ConditionSpec spec_{};
  bool armed_ = false;
  bool have_previous_ = false;
  bool previous_beyond_ = false;
};

// "following_error_m above 0.001" (the level with %.9g), for files, status and logs.
[[nodiscard]] std::string describe(const ConditionSpec& spec);

}  // namespace hsa::daemon
