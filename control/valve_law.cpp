#include "control/valve_law.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::control {

ValveLaw::ValveLaw(const ValveLawParams& p) : params_(p) {
  // Written as negated comparisons so that NaN is rejected too.
  if (!(p.period_s > 0.0)) throw std::invalid_argument("ValveLaw: period must be > 0");
  if (!(p.max_current_a > 0.0)) throw std::invalid_argument("ValveLaw: I_max must be > 0");
  if (!(p.bias_current_a >= 0.0 && p.bias_current_a <= p.max_current_a))
    throw std::invalid_argument("ValveLaw: bias current must lie in [0, I_max]");
  if (!(p.dead_band_error_m > 0.0))
    throw std::invalid_argument("ValveLaw: dead band error scale must be > 0");
  for (double gain : {p.feedforward_a_per_m, p.integral_a_per_m_s, p.proportional_a_per_m,
                      p.dead_band_compensation_a, p.velocity_a_per_m_s, p.acceleration_a_per_m_s2}) {
    if (!(gain >= 0.0)) throw std::invalid_argument("ValveLaw: gains must be >= 0");
  }
  current_ = p.bias_current_a;
}

void ValveLaw::reset(double integral_m_s) {
  integral_ = integral_m_s;
  error_ = 0.0;
  saturated_ = false;
}

double ValveLaw::error_function(double error_m) const {
  return params_.proportional_a_per_m * error_m +
         params_.dead_band_compensation_a * std::tanh(error_m / params_.dead_band_error_m);
}

double ValveLaw::update(double reference_m, const PredictorOutput& predicted) {
  const ValveLawParams& p = params_;
  error_ = reference_m - predicted.position_m;
  const double unclamped = p.bias_current_a + p.feedforward_a_per_m * reference_m +
                           p.integral_a_per_m_s * integral_ + error_function(error_) -
                           p.velocity_a_per_m_s * predicted.velocity_m_s -
                           p.acceleration_a_per_m_s2 * predicted.acceleration_m_s2;
  current_ = std::clamp(unclamped, 0.0, p.max_current_a);
  saturated_ = unclamped > p.max_current_a || unclamped < 0.0;
  if (saturated_) ++saturation_count_;

  // Eq 31 integrates after the output, so this sample's error acts from the next sample on.
  const bool pushes_up = unclamped > p.max_current_a && error_ > 0.0;
  const bool pushes_down = unclamped < 0.0 && error_ < 0.0;
  if (!pushes_up && !pushes_down) integral_ += p.period_s * error_;
  return current_;
}

}  // namespace hsa::control
