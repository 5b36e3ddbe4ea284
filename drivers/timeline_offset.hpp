// Where CLOCK_MONOTONIC sits on the daemon's timeline, for a driver whose own thread stamps its
// samples on CLOCK_MONOTONIC (a bus poller) and whose read() must give them timestamps on the
// timeline the cycle's `t` is on.
//
// Each read() measures offset = t - now, where `now` is CLOCK_MONOTONIC inside read(). That is
// the true offset less however long the cycle ran before reaching read(): microseconds normally,
// but tens of milliseconds when the host preempts the RT thread mid-cycle (a VM whose CPU was
// taken). Subtracting a sample's age measured at such a read, as `t - (now - acquired)`, places
// the sample that much too early, and the interval to the previous sample shrinks by the same
// amount: a rod that travelled 8.8 mm in 40 ms read as 8.8 mm in 2 ms, an impossible jump. Each
// measurement can only be short, never long, so the largest of the last kWindow is the estimate:
// one preempted read cannot move it, and a caller whose `t` runs at another rate than
// CLOCK_MONOTONIC (a test stepping `t` by hand) is followed within kWindow reads.
//
// A sample acquired while the cycle was held up is then stamped after the cycle's `t`; its age
// at `t` reads as zero (input_age.hpp), which is what it is.
//
// RT-safe: fixed storage, no allocation, no lock.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "drivers/clock.hpp"

namespace hsa::io {

class TimelineOffset {
 public:
  static constexpr std::size_t kWindow = 16;

  // One read(): `t` the cycle's time, `now_ns` CLOCK_MONOTONIC at the read. Returns the estimate
  // with this measurement in it.
  std::int64_t measure(Timestamp t, std::int64_t now_ns) noexcept {
    measured_[next_] = t.count() - now_ns;
    next_ = (next_ + 1) % kWindow;
    count_ = std::min(count_ + 1, kWindow);
    estimate_ = *std::max_element(measured_.begin(), measured_.begin() + static_cast<std::ptrdiff_t>(count_));
    return estimate_;
  }

  // A CLOCK_MONOTONIC time on the daemon's timeline, by the last estimate. Only after measure().
  [[nodiscard]] Timestamp on_timeline(std::int64_t monotonic) const noexcept {
    return Timestamp{monotonic + estimate_};
  }

 private:
  std::array<std::int64_t, kWindow> measured_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
  std::int64_t estimate_ = std::numeric_limits<std::int64_t>::min();
};

}  // namespace hsa::io
