// The supervisor's thresholds for its tests: streaks of a few cycles and bounds of a few periods,
// so a test reaches every fault class within a few hundred cycles.
#pragma once

#include <cstdint>

#include "daemon/supervisor/axis_supervisor.hpp"

namespace hsa::daemon::test {

inline constexpr std::int64_t kSupervisorPeriodNs = 100'000;  // 100 µs

inline SupervisorParams short_supervisor_params() {
  SupervisorParams p;
  p.following_error_cycles = 5;
  p.encoder_stale_cycles = 3;
  p.saturation_cycles = 4;
  p.overrun_streak_max = 3;
  p.setpoint_timeout_ns = 10 * kSupervisorPeriodNs;
  p.input_stale_ns = 5 * kSupervisorPeriodNs;
  p.max_blind_time_ns = 50 * kSupervisorPeriodNs;  // 5 ms
  return p;
}

}  // namespace hsa::daemon::test
