#include "control/valve_time_optimal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "control/valve_law.hpp"

namespace hsa::control {

ValveTimeOptimal::ValveTimeOptimal(const ValveTimeOptimalParams& p, double period_s, double max_current_a)
    : params_(p), period_s_(period_s), max_current_a_(max_current_a) {
  if (!p.enabled) return;
  // Negated comparisons, so that NaN is refused too.
  if (!(p.gain_m_per_a > 0.0) || !(p.natural_frequency_hz > 0.0) || !(p.damping_ratio > 0.0) ||
      !(p.magnetic_lag_s > 0.0) || !(p.width_a >= 0.0) || !(p.delay_s >= 0.0) || !std::isfinite(p.rest_position_m))
    throw std::invalid_argument("ValveTimeOptimal: g, f0, ζ, τa must be > 0, w and the delay >= 0");
  if (!(p.trigger_m > 0.0) || !(p.margin_m >= 0.0) || !(p.overshoot_m >= 0.0) || p.horizon_samples < 1)
    throw std::invalid_argument("ValveTimeOptimal: trigger must be > 0, margins >= 0, horizon >= 1 sample");
  if (!(period_s > 0.0) || !(max_current_a > 0.0))
    throw std::invalid_argument("ValveTimeOptimal: period and I_max must be > 0");
  const double samples = std::round(p.delay_s / period_s);
  if (samples > kMaxDelaySamples)
    throw std::invalid_argument("ValveTimeOptimal: the delay must be at most 16 samples");
  delay_samples_ = static_cast<int>(samples);
  w0_ = 2.0 * std::numbers::pi * p.natural_frequency_hz;
  lag_factor_ = -std::expm1(-period_s / p.magnetic_lag_s);
}

void ValveTimeOptimal::reset() noexcept {
  started_ = false;
  mode_ = Mode::track;
  handed_back_ = false;
  offset_m_ = 0.0;
}

void ValveTimeOptimal::step(ModelState& s, double current_a, bool averaged) const noexcept {
  const ValveTimeOptimalParams& p = params_;
  if (averaged) {
    s.play = current_a - 0.5 * p.width_a;  // the linear law's dither moves the play every half period
  } else if (current_a > s.play + p.width_a) {
    s.play = current_a - p.width_a;  // rising: the play sits w below the current (eq 6)
  } else if (current_a < s.play) {
    s.play = current_a;  // falling: at it
  }
  s.force += lag_factor_ * (s.play - s.force);
  s.a = w0_ * w0_ * (p.rest_position_m + p.gain_m_per_a * s.force + offset_m_ - s.x) - 2.0 * p.damping_ratio * w0_ * s.v;
  s.v += period_s_ * s.a;
  s.x += period_s_ * s.v;
}

void ValveTimeOptimal::commanded(double current_a) noexcept {
  if (!params_.enabled) return;
  if (!started_) {  // from rest on the first current: the delay line full of it, the play averaged by the dither
    delay_line_.fill(current_a);
    play_ = force_ = current_a - 0.5 * params_.width_a;
    started_ = true;
  }
  // The command δ ago enters the valve during this sample; this one waits δ.
  double entering = current_a;
  if (delay_samples_ > 0) {
    entering = delay_line_[static_cast<std::size_t>(head_)];
    delay_line_[static_cast<std::size_t>(head_)] = current_a;
    head_ = (head_ + 1) % delay_samples_;
  }
  ModelState s{play_, force_, 0.0, 0.0, 0.0};
  step(s, entering, false);
  play_ = s.play;
  force_ = s.force;
}

double ValveTimeOptimal::predict(const ValveLinearLaw* linear, double constant_a, double target_m, double direction,
                                 const PredictorOutput& from) const noexcept {
  ModelState s{play_, force_, from.position_m, from.velocity_m_s, from.acceleration_m_s2};
  double peak = direction * s.x;
  for (int k = 0; k < params_.horizon_samples; ++k) {
    const bool pending = k < delay_samples_;
    double current = constant_a;
    if (pending) {
      current = delay_line_[static_cast<std::size_t>((head_ + k) % delay_samples_)];
    } else if (linear != nullptr) {
      const double e = target_m - s.x;
      current = std::clamp(linear->hold_current_a + linear->feedforward_a_per_m * target_m +
                               linear->proportional_a_per_m * e +
                               linear->dead_band_compensation_a * std::tanh(e / linear->dead_band_error_m) -
                               linear->velocity_a_per_m_s * s.v - linear->acceleration_a_per_m_s2 * s.a,
                           0.0, max_current_a_);
    }
    step(s, current, !pending && linear != nullptr);
    peak = std::max(peak, direction * s.x);
    // Under a constant braking current the first turn of the velocity is the stop; the linear law
    // may turn the spool back towards the target, so its prediction runs the whole horizon.
    if (!pending && linear == nullptr && direction * s.v <= 0.0) break;
  }
  return peak;
}

double ValveTimeOptimal::stop_under(double current_a, double direction, const PredictorOutput& from) const noexcept {
  return predict(nullptr, current_a, 0.0, direction, from);
}

double ValveTimeOptimal::stop_under_linear(const ValveLinearLaw& linear, double target_m, double direction,
                                           const PredictorOutput& from) const noexcept {
  return predict(&linear, 0.0, target_m, direction, from);
}

double ValveTimeOptimal::update(double reference_m, double filtered_reference_m, const PredictorOutput& predicted,
                                const ValveLinearLaw& linear) noexcept {
  constexpr double kLinear = std::numeric_limits<double>::quiet_NaN();
  handed_back_ = false;
  if (!params_.enabled || !started_) return kLinear;
  const ValveTimeOptimalParams& p = params_;
  const double x = predicted.position_m;
  const bool jumped = mode_ == Mode::track ? std::abs(reference_m - filtered_reference_m) > p.trigger_m
                                           : std::abs(reference_m - target_) > p.trigger_m;
  if (jumped && std::abs(reference_m - x) > p.trigger_m) {
    if (mode_ == Mode::track) {
      // The spool rests on the previous target: what the model's equilibrium misses of it is b.
      offset_m_ = x + (predicted.acceleration_m_s2 + 2.0 * p.damping_ratio * w0_ * predicted.velocity_m_s) / (w0_ * w0_) -
                  p.rest_position_m - p.gain_m_per_a * force_;
    }
    target_ = reference_m;
    direction_ = reference_m > x ? 1.0 : -1.0;
    mode_ = Mode::drive;
    ++moves_;
  }
  if (mode_ == Mode::track) return kLinear;
  const double drive = direction_ > 0.0 ? max_current_a_ : 0.0;
  const double brake = direction_ > 0.0 ? 0.0 : max_current_a_;
  if (mode_ == Mode::drive && stop_under(brake, direction_, predicted) >= direction_ * target_ - p.margin_m)
    mode_ = Mode::brake;
  if (mode_ == Mode::brake &&
      (direction_ * predicted.velocity_m_s <= 0.0 ||
       stop_under_linear(linear, target_, direction_, predicted) <= direction_ * target_ + p.overshoot_m)) {
    mode_ = Mode::track;
    handed_back_ = true;
    return kLinear;
  }
  return mode_ == Mode::drive ? drive : brake;
}

ValveTimeOptimalParams identified_time_optimal(const IdentifiedValve& v, double period_s) {
  ValveTimeOptimalParams t;
  t.enabled = true;
  t.gain_m_per_a = v.gain_m_per_a;
  t.rest_position_m = v.rest_position_m;
  t.natural_frequency_hz = v.natural_frequency_hz;
  t.damping_ratio = v.damping_ratio;
  t.magnetic_lag_s = v.magnetic_lag_s;
  t.width_a = v.width_a;
  t.delay_s = v.delay_s;
  // No spool of this valve moves faster than g·I_max·ω0 (a spring–mass from rest under a force
  // step F moves at most at F/(m·ω0)): a reference further than that in one sample has jumped.
  t.trigger_m = v.gain_m_per_a * v.current_max_a * 2.0 * std::numbers::pi * v.natural_frequency_hz * period_s;
  // Brake to stop d_on short of the target: the predictor's state lags the spool, and the last
  // stretch is the linear law's (without it the square overshot by 22 %).
  t.margin_m = t.trigger_m;
  t.overshoot_m = 0.0;
  t.horizon_samples = 200;
  return t;
}

// ValveLaw's hook (valve_law.hpp): while a move runs, its current replaces the linear law's, the
// integrator holds and the dither's phase runs on; on the hand-back the reference filter rests on
// the target, so the linear law starts from the hold current the prediction assumed.
bool ValveLaw::time_optimal_move(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed) noexcept {
  if (!params_.time_optimal.enabled) return false;
  const ValveLawParams& p = params_;
  const ValveLinearLaw linear{
      .hold_current_a = p.bias_current_a + p.integral_a_per_m_s * integral_,
      .feedforward_a_per_m = p.feedforward_a_per_m,
      .proportional_a_per_m = p.proportional_a_per_m,
      .dead_band_compensation_a = p.dead_band_compensation_a,
      .dead_band_error_m = p.dead_band_error_m,
      .velocity_a_per_m_s = p.velocity_a_per_m_s,
      .acceleration_a_per_m_s2 = p.acceleration_a_per_m_s2};
  const double move = time_optimal_.update(reference_m, ref_started_ ? ref_position_ : reference_m, predicted, linear);
  if (time_optimal_.handed_back()) {
    ref_position_ = time_optimal_.target_m();
    ref_velocity_ = ref_acceleration_ = 0.0;
    ref_started_ = true;
  }
  if (std::isnan(move)) return false;
  (void)dither(elapsed);
  error_ = time_optimal_.target_m() - predicted.position_m;
  current_ = move;
  saturated_ = false;  // a chosen current, not a clipped demand
  integrated_ = false;
  time_optimal_.commanded(current_);
  return true;
}

}  // namespace hsa::control
