// CLOCK_MONOTONIC in nanoseconds, read the same way on the bus thread and the RT thread.
//
// The daemon's cycle time `t` counts from the daemon's own epoch, which a driver does not know,
// so sample ages are measured on the raw monotonic clock that both threads share and only then
// placed on the daemon's timeline (timestamp = t - age). clock_gettime on CLOCK_MONOTONIC is a
// vDSO call: no system call, no lock, safe on the RT path.
#pragma once

#include <time.h>

#include <cstdint>

namespace hsa::io::modbus {

inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace hsa::io::modbus
