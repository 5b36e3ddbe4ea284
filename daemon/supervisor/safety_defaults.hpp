// The default fault thresholds of an axis, in one place. The configuration ([axes.safety]) falls
// back to these, and SupervisorParams' defaults are these at the default base period, so a test
// that builds a supervisor without a configuration judges as an unconfigured axis would.
// Thresholds that are times are given in seconds; the supervisor converts them to the base ticks
// it counts (at least one).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hsa::daemon::safety_defaults {

inline constexpr double kBasePeriodS = 100e-6;        // the default base tick (realtime.base_period_us)
inline constexpr double kEncoderStaleS = 0.001;       // no fresh encoder sample for this long faults
inline constexpr double kFollowingErrorS = 0.010;     // over max_following_error_m this long faults
inline constexpr double kInputStaleS = 0.1;           // any bound input without a new timestamp
inline constexpr double kMaxBlindTimeS = 0.005;       // ENABLED: longest time between two cycles
inline constexpr double kCurrentSaturationS = 0.5;    // the valve command saturated this long faults
inline constexpr std::uint32_t kOverrunStreak = 10;   // consecutive RT overruns that fault
inline constexpr double kDefaultRampS = 0.1;          // a move without an acceleration reaches its speed in this
inline constexpr double kDefaultJerkRampS = 0.05;     // and its acceleration in this (the jerk bound)
inline constexpr double kStartupTimeoutS = 2.0;       // INIT waits this long for every input's first sample
inline constexpr double kSetpointTimeoutS = 0.5;      // setpoint silence that holds the position

// Base ticks in `seconds`, rounded up, at least one: a threshold never becomes "at once".
inline std::uint32_t ticks_in(double seconds, double base_period_s) {
  return static_cast<std::uint32_t>(std::max(1.0, std::ceil(seconds / base_period_s - 1e-9)));
}

}  // namespace hsa::daemon::safety_defaults
