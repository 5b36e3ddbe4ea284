// Chooses which RT telemetry samples are published: the first one in each window of `factor`
// base ticks.
//
// Decimating on the RT tick index rather than on wall-clock timestamps keeps the published rate
// exact whatever the wake-up jitter, whether the RT thread pushes every tick or every 10th, and
// after ring drops (a lost sample shifts the choice to the next sample in its window instead of
// skipping the window).
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
  bool take(std::uint64_t tick) {
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
