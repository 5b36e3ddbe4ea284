// Time as the I/O layer sees it: integer nanoseconds on the daemon's monotonic clock.
//
// Integer nanoseconds rather than double seconds so that a 100 µs period summed over days of
// running does not drift, and so that a timestamp compares exactly with the cycle time it came from.
#pragma once

#include <chrono>

namespace hsa::io {

using Duration = std::chrono::nanoseconds;
using Timestamp = std::chrono::nanoseconds;  // since the daemon's epoch on CLOCK_MONOTONIC

// Seconds as a double, for models and laws that integrate in SI units.
constexpr double to_seconds(Duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace hsa::io
