#pragma once

// The valve loop's learning law, run on the RT thread (control/valve_learning_design.hpp designs
// it offline and states the algorithm): each sample it returns the reference correction
//
//   u(i) = Σ_{j=−M..M} q_j·u(i − N − j) + Σ_{j=−M..M} h_j·e(i − N − j),   e(i) = r(i − D) − x(i)
//
// from the last period's corrections and errors (the samples ahead of i − N, j < 0, are in that period,
// which is what lets q and h be non-causal), then stores u(i), e(i) and r(i). Its ring buffers hold
// N + M + 1 samples and are sized in the constructor: update() does not allocate.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace hsa::control {

class ValveLearning {
 public:
  ValveLearning() = default;  // off: update() returns 0
  // Throws std::invalid_argument unless N >= 4, 0 <= D < N, and q, h have the same odd length
  // 2M + 1 with M < N.
  ValveLearning(int period_samples, int delay_samples, std::vector<double> filter, std::vector<double> kernel);

  [[nodiscard]] bool on() const { return period_ > 0; }

  // The correction for this sample's reference r(i), x(i) the position the law sees now.
  // `elapsed` > 1: the missed samples are filled with this sample's reference, error and
  // correction (at most one buffer's worth), so the buffer stays aligned with the period.
  double update(double reference_m, double position_m, std::uint64_t elapsed = 1) noexcept;

  // e(i) of the last update.
  [[nodiscard]] double error() const { return error_; }

  // Forgets everything learned.
  void reset() noexcept;

 private:
  [[nodiscard]] std::size_t at(std::int64_t back) const noexcept;  // index of sample i − back
  void store(double u, double e, double r) noexcept;
  int period_ = 0, delay_ = 0, half_ = 0;
  std::vector<double> filter_, kernel_;
  std::vector<double> u_, e_, r_;
  std::size_t head_ = 0;  // where sample i goes
  std::uint64_t count_ = 0;
  double error_ = 0.0;
};

}  // namespace hsa::control
