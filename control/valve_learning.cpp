#include "control/valve_learning.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace hsa::control {

ValveLearning::ValveLearning(int period_samples, int delay_samples, std::vector<double> filter,
                             std::vector<double> kernel)
    : period_(period_samples), delay_(delay_samples), filter_(std::move(filter)), kernel_(std::move(kernel)) {
  if (period_ < 4) throw std::invalid_argument("ValveLearning: the period must be at least 4 samples");
  if (delay_ < 0 || delay_ >= period_) throw std::invalid_argument("ValveLearning: the delay must lie in [0, N)");
  if (filter_.size() % 2 != 1 || filter_.size() != kernel_.size())
    throw std::invalid_argument("ValveLearning: Q and the kernel must have the same odd length 2M + 1");
  half_ = static_cast<int>(filter_.size() / 2);
  if (half_ >= period_) throw std::invalid_argument("ValveLearning: the filters must be shorter than the period");
  const std::size_t size = static_cast<std::size_t>(period_ + half_ + 1);
  u_.assign(size, 0.0);
  e_.assign(size, 0.0);
  r_.assign(size, 0.0);
}

void ValveLearning::reset() noexcept {
  std::fill(u_.begin(), u_.end(), 0.0);
  std::fill(e_.begin(), e_.end(), 0.0);
  std::fill(r_.begin(), r_.end(), 0.0);
  head_ = 0;
  count_ = 0;
  error_ = 0.0;
}

std::size_t ValveLearning::at(std::int64_t back) const noexcept {
  const auto size = static_cast<std::int64_t>(u_.size());
  return static_cast<std::size_t>(((static_cast<std::int64_t>(head_) - back) % size + size) % size);
}

void ValveLearning::store(double u, double e, double r) noexcept {
  u_[head_] = u;
  e_[head_] = e;
  r_[head_] = r;
  head_ = (head_ + 1) % u_.size();
  ++count_;
}

double ValveLearning::update(double reference_m, double position_m, std::uint64_t elapsed) noexcept {
  if (!on()) return 0.0;
  // Missed samples: hold this one's values over them (as the output was held).
  const std::uint64_t missed = std::min<std::uint64_t>(elapsed > 1 ? elapsed - 1 : 0, u_.size());
  for (std::uint64_t k = 0; k < missed; ++k) store(u_[at(1)], e_[at(1)], reference_m);
  double u = 0.0;
  // Until a whole period plus M is stored, the buffer's older half is the start's zeros.
  for (int j = -half_; j <= half_; ++j) {
    const std::size_t k = at(period_ + j);  // sample i − N − j: a convolution, as designed
    u += filter_[static_cast<std::size_t>(j + half_)] * u_[k] + kernel_[static_cast<std::size_t>(j + half_)] * e_[k];
  }
  // e(i) = r(i − D) − x(i); before D samples exist, the reference starts where it is.
  const double delayed =
      delay_ == 0 ? reference_m : (count_ >= static_cast<std::uint64_t>(delay_) ? r_[at(delay_)] : reference_m);
  error_ = delayed - position_m;
  store(u, error_, reference_m);
  return u;
}

}  // namespace hsa::control
