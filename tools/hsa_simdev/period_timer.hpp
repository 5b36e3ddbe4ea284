// The fixed-rate pace of hsa-simdev's threads (the rig model and the CAN side), on CLOCK_MONOTONIC
// with absolute deadlines so that the rate does not drift with the work done in each period.
#pragma once

#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstdint>

#include "drivers/clock.hpp"

namespace hsa::simdev {

class PeriodTimer {
 public:
  explicit PeriodTimer(double period_s)
      : period_ns_(static_cast<std::int64_t>(std::llround(period_s * 1e9))), next_ns_(io::monotonic_ns()) {}

  // Sleeps until the next period boundary. More than 100 periods behind (a host that stalled the
  // process), it moves the boundary to now instead of running the missed periods in a burst, and
  // returns true.
  bool wait_next() {
    next_ns_ += period_ns_;
    const timespec deadline{static_cast<time_t>(next_ns_ / 1'000'000'000), static_cast<long>(next_ns_ % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
    const std::int64_t now = io::monotonic_ns();
    if (now - next_ns_ <= 100 * period_ns_) return false;
    next_ns_ = now;
    return true;
  }

 private:
  std::int64_t period_ns_;
  std::int64_t next_ns_;
};

}  // namespace hsa::simdev
