// Chooses which RT cycles publish an axis's telemetry: the first cycle in each window of `factor`
// base ticks (the axis's ticks_per_telemetry). The one place telemetry is decimated.
//
// Deciding on the RT tick index rather than on wall-clock timestamps keeps the published rate
// exact whatever the wake-up jitter, and a cycle that an overrun skipped does not lose its window:
// the next cycle in the window publishes instead, and a subscriber sees a gap only when a stall
// skipped the whole window. Real-time safe: two integers, no allocation.
#pragma once

#include <cstdint>
#include <stdexcept>

namespace hsa::daemon {

class TickDecimator {
 public:
  // Throws std::invalid_argument for factor 0.
  explicit TickDecimator(std::uint64_t factor) : factor_(factor) {
    if (factor == 0) throw std::invalid_argument("TickDecimator: factor must be at least 1");
  }

  // True when the sample at `tick` is the first seen in its window.
  bool take(std::uint64_t tick) noexcept {
    const std::uint64_t window = tick / factor_;
    if (has_window_ && window == window_) return false;
    has_window_ = true;
    window_ = window;
    return true;
  }

  [[nodiscard]] std::uint64_t factor() const { return factor_; }

 private:
  std::uint64_t factor_;
  bool has_window_ = false;
  std::uint64_t window_ = 0;
};

}  // namespace hsa::daemon
