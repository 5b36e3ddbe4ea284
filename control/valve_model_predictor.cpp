#include "control/valve_model_predictor.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::control {

namespace {

int checked_delay_samples(const ValveModelPredictorParams& p, double period_s) {
  if (!(period_s > 0.0)) throw std::invalid_argument("ValveModelPredictor: the period must be positive");
  const IdentifiedValve& v = p.valve;
  if (!(v.gain_m_per_a > 0.0 && v.natural_frequency_hz > 0.0 && v.damping_ratio > 0.0 && v.magnetic_lag_s > 0.0))
    throw std::invalid_argument("ValveModelPredictor: the valve's g, f0, zeta and tau_a must be positive");
  if (!(v.width_a >= 0.0 && v.delay_s >= 0.0) || !std::isfinite(v.rest_position_m))
    throw std::invalid_argument("ValveModelPredictor: the valve's w and delay must be >= 0 and X_min finite");
  const long samples = std::lround(v.delay_s / period_s);
  if (samples > ValveModelPredictor::kMaxDelaySamples)
    throw std::invalid_argument("ValveModelPredictor: the valve's delay is longer than 16 samples");
  return static_cast<int>(samples);
}

}  // namespace

ValveModelPredictor::ValveModelPredictor(const ValveModelPredictorParams& params, double period_s)
    : params_(params),
      gains_(predictor_gains(params.gamma)),
      period_s_(period_s),
      w0_(2.0 * std::numbers::pi * params.valve.natural_frequency_hz),
      lag_factor_(0.0),
      delay_line_(checked_delay_samples(params, period_s)) {
  lag_factor_ = -std::expm1(-period_s_ / params_.valve.magnetic_lag_s);
}

void ValveModelPredictor::reset(double position_m) noexcept {
  x_ = position_m;
  v_ = d_ = q_ = 0.0;
  force_ = 0.0;
  started_ = false;
}

PredictorOutput ValveModelPredictor::update(double measured_position_m) noexcept {
  const IdentifiedValve& m = params_.valve;
  const double t2 = period_s_ * period_s_;
  const double model_acceleration = started_ ? w0_ * w0_ * (m.rest_position_m + m.gain_m_per_a * force_ - x_) -
                                                   2.0 * m.damping_ratio * w0_ * (v_ / period_s_)
                                             : 0.0;
  const double e = measured_position_m - x_;
  // Eq 16's third row of C_m, D_m, plus the model's part.
  const double acceleration = model_acceleration * t2 + d_ + gains_.l_a * e + gains_.m_a * q_;
  const PredictorOutput out{.position_m = x_, .velocity_m_s = v_ / period_s_, .acceleration_m_s2 = acceleration / t2};
  // Eq 15 with A, L of eq 16: v's row takes the whole acceleration estimate.
  const double x = x_ + v_;
  const double v = v_ + acceleration;
  const double d = d_ + gains_.l_d * e + gains_.m_d * q_;
  const double q = (1.0 - gains_.beta) * q_ + e;
  x_ = x;
  v_ = v;
  d_ = d;
  q_ = q;
  return out;
}

void ValveModelPredictor::commanded(double current_a) noexcept {
  const double half_width = 0.5 * params_.valve.width_a;
  if (!started_) {  // from rest on the first current: the delay line full of it, the force settled
    delay_line_.fill(current_a);
    force_ = current_a - half_width;
    started_ = true;
  }
  force_ += lag_factor_ * ((delay_line_.push(current_a) - half_width) - force_);
}

}  // namespace hsa::control
