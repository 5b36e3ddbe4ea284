#include "daemon/recorder/capture_condition.hpp"

#include <cstdio>

#include "daemon/recorder/recorder_signals.hpp"

namespace hsa::daemon {

void CaptureCondition::arm(const ConditionSpec& spec) noexcept {
  spec_ = spec;
  armed_ = spec.signal >= 0 && static_cast<std::size_t>(spec.signal) < kRecorderSignalCount;
  have_previous_ = false;
  previous_beyond_ = false;
}

bool CaptureCondition::evaluate(const RecorderRow& row) noexcept {
  if (!armed_) return false;
  const double v = kRecorderSignals[spec_.signal].read(row);
  // NaN compares false both ways: never beyond.
  const bool beyond = spec_.crossing == Crossing::above ? v > spec_.level : v < spec_.level;
  const bool fired = have_previous_ && !previous_beyond_ && beyond;
  have_previous_ = true;
  previous_beyond_ = beyond;
  if (fired && !spec_.repeat) armed_ = false;
  return fired;
}

std::string describe(const ConditionSpec& spec) {
  if (spec.signal < 0 || static_cast<std::size_t>(spec.signal) >= kRecorderSignalCount) return "?";
  char text[96];
  std::snprintf(text, sizeof text, "%s %s %.9g", kRecorderSignals[spec.signal].name,
                spec.crossing == Crossing::above ? "above" : "below", spec.level);
  return text;
}

}  // namespace hsa::daemon
