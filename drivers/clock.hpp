// Time as the I/O layer sees it: integer nanoseconds on the daemon's monotonic clock.
//
// Integer nanoseconds rather than double seconds so that a 100 µs period summed over days of
// running does not drift, and so that a timestamp compares exactly with the cycle time it came from.
#pragma once

#include <time.h>

#include <chrono>
#include <cstdint>

namespace hsa::io {

using Duration = std::chrono::nanoseconds;
using Timestamp = std::chrono::nanoseconds;  // since the daemon's epoch on CLOCK_MONOTONIC

// Seconds as a double, for models and laws that integrate in SI units.
constexpr double to_seconds(Duration d) { return std::chrono::duration<double>(d).count(); }

// CLOCK_MONOTONIC in nanoseconds, the raw clock the daemon's epoch is taken on. A vDSO call: no
// system call, no lock, safe on the RT path and on a driver's own threads alike.
inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace hsa::io
