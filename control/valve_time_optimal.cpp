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
  if (!(p.trigger_m > 0.0) || !(p.margin_m >= 0.0) || p.horizon_samples < 1)
    throw std::invalid_argument("ValveTimeOptimal: trigger must be > 0, margins >= 0, horizon >= 1 sample");
  if (!(period_s > 0.0) || !(max_current_a > 0.0))
    throw std::invalid_argument("ValveTimeOptimal: period and I_max must be > 0");
  const double samples = std::round(p.delay_s / period_s);
  if (samples > kMaxDelaySamples)
    throw std::invalid_argument("ValveTimeOptimal: the delay must be at most 16 samples");
  delay_line_ = CommandDelayLine(static_cast<int>(samples));
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
    model_ = ModelState{};
    model_.play = model_.force = current_a - 0.5 * params_.width_a;
    model_.x = params_.rest_position_m + params_.gain_m_per_a * model_.force;
    offset_m_ = 0.0;
    started_ = true;
  }
  // The command δ ago enters the valve during this sample; this one waits δ.
  step(model_, delay_line_.push(current_a), false);
}

ValveTimeOptimal::ModelState ValveTimeOptimal::after_pending() const noexcept {
  ModelState s = model_;
  for (int k = 0; k < delay_line_.samples(); ++k) step(s, delay_line_.pending(k), false);
  return s;
}

double ValveTimeOptimal::peak_under(ModelState s, double current_a, double direction, int* steps) const noexcept {
  double peak = direction * s.x;
  for (int k = 0; k < params_.horizon_samples && *steps > 0; ++k, --*steps) {
    step(s, current_a, false);
    peak = std::max(peak, direction * s.x);
    if (direction * s.v <= 0.0) break;  // the first turn of the velocity is the stop
  }
  return peak;
}

bool ValveTimeOptimal::rebuilt(ModelState s) const noexcept {
  step(s, full_effort(), false);
  return direction_ * s.force >= direction_ * hold_force_a_;
}

double ValveTimeOptimal::peak_after_rebuild(ModelState s, int* steps) const noexcept {
  double peak = direction_ * s.x;
  for (int k = 0; k < params_.horizon_samples && *steps > 0; ++k, --*steps) {
    if (rebuilt(s)) return std::max(peak, peak_under(s, settle_, direction_, steps));
    step(s, full_effort(), false);
    peak = std::max(peak, direction_ * s.x);
    if (direction_ * s.v <= 0.0) break;
  }
  return peak;
}

double ValveTimeOptimal::stop_under(double current_a, double direction, const PredictorOutput& from) const noexcept {
  ModelState s = model_;
  s.x = from.position_m;
  s.v = from.velocity_m_s;
  s.a = from.acceleration_m_s2;
  double peak = direction * s.x;
  for (int k = 0; k < delay_line_.samples(); ++k) {
    step(s, delay_line_.pending(k), false);
    peak = std::max(peak, direction * s.x);
  }
  int steps = params_.horizon_samples;
  return std::max(peak, peak_under(s, current_a, direction, &steps));
}

double ValveTimeOptimal::hold_current(double target_m, double direction) const noexcept {
  const ValveTimeOptimalParams& p = params_;
  const double force = (target_m - p.rest_position_m - offset_m_) / p.gain_m_per_a;
  // Rising, the play sits w below the current (eq 6); falling, at it.
  return std::clamp(force + (direction > 0.0 ? p.width_a : 0.0), 0.0, max_current_a_);
}

// Braking longer only lowers where the hold current then stops the model (less speed and less
// force current to stop), so among the braking lengths that do not pass the target the longest is
// the one to try: the move can still land if the hold current stops the model short of the target
// from there. One braking run and one hold run, instead of a hold run per braking length (which
// cost up to kPredictionBudget steps a sample). Where that monotony failed, this would brake
// early: the safe side.
bool ValveTimeOptimal::can_drive_on() const noexcept {
  const double s_target = direction_ * target_;
  ModelState s = after_pending();
  step(s, full_effort(), false);  // this sample at full effort
  const double brake = direction_ > 0.0 ? 0.0 : max_current_a_;
  for (int j = 0; j < params_.horizon_samples; ++j) {
    ModelState next = s;
    step(next, brake, false);
    if (direction_ * next.x > s_target) break;  // braked any longer it passes: s is the last chance
    if (direction_ * next.v <= 0.0) return true;  // stops short under full braking
    s = next;
  }
  int steps = kPredictionBudget;
  return peak_under(s, hold_, direction_, &steps) <= s_target - params_.margin_m;
}

double ValveTimeOptimal::update(double reference_m, double filtered_reference_m, const PredictorOutput& predicted) noexcept {
  constexpr double kLinear = std::numeric_limits<double>::quiet_NaN();
  handed_back_ = false;
  if (!params_.enabled || !started_) return kLinear;
  const ValveTimeOptimalParams& p = params_;
  const bool jumped = mode_ == Mode::track ? std::abs(reference_m - filtered_reference_m) > p.trigger_m
                                           : std::abs(reference_m - target_) > p.trigger_m;
  const double x = mode_ == Mode::track ? predicted.position_m : model_.x;
  if (jumped && std::abs(reference_m - x) > p.trigger_m) {
    if (mode_ == Mode::track) {
      // The spool rests on the previous target: the model, run on all along, sits at its own
      // equilibrium, and what it misses of the measured spool is b (the identified X_min or g
      // slightly off). Its velocity and acceleration stay the model's: at rest the predictor's
      // are the LVDT's noise and the dither's ripple, and a/ω0² of them would move b by tens of µm.
      offset_m_ += x - model_.x;
      model_.x = x;
    }
    target_ = reference_m;
    direction_ = reference_m > x ? 1.0 : -1.0;
    hold_ = hold_current(target_, direction_);
    settle_ = hold_current(target_, -direction_);
    // c_h, within what full effort reaches (the play's I_max − w rising, 0 falling) less 1 % of
    // I_max: beyond it a rebuild approaching its limit would never end the move.
    const double margin = 0.01 * max_current_a_;
    const double held = (target_ - p.rest_position_m - offset_m_) / p.gain_m_per_a;
    hold_force_a_ = direction_ > 0.0 ? std::min(held, max_current_a_ - p.width_a - margin) : std::max(held, margin);
    mode_ = Mode::drive;
    start_m_ = model_.x;
    ++moves_;
  }
  if (mode_ == Mode::track) return kLinear;
  // A target beyond what full effort reaches: the model, having moved, stops short of it under
  // the drive. The linear law takes the rest (it saturates there as the drive would).
  if (mode_ == Mode::drive && direction_ * (model_.x - start_m_) > p.trigger_m && direction_ * model_.v <= 0.0) {
    mode_ = Mode::track;
    handed_back_ = true;
    return kLinear;
  }
  if (mode_ == Mode::drive && !can_drive_on()) mode_ = Mode::brake;
  if (mode_ == Mode::brake) {
    int steps = kPredictionBudget;
    if (peak_after_rebuild(after_pending(), &steps) <= direction_ * target_ - p.margin_m) mode_ = Mode::rebuild;
  }
  if (mode_ == Mode::rebuild && rebuilt(after_pending())) mode_ = Mode::settle;
  // Not during the rebuild: a spool stopped there, its force current short of c_h, would be thrown
  // back by the spring; the rebuild (towards the target, c never past c_h) runs on first.
  if (mode_ == Mode::settle && direction_ * model_.v <= 0.0) {
    mode_ = Mode::track;
    handed_back_ = true;
    return kLinear;
  }
  switch (mode_) {
    case Mode::drive:
    case Mode::rebuild: return full_effort();
    case Mode::brake: return direction_ > 0.0 ? 0.0 : max_current_a_;
    default: return settle_;
  }
}

ValveTimeOptimalParams time_optimal_on(const IdentifiedValve& v) {
  ValveTimeOptimalParams t;
  t.enabled = true;
  t.gain_m_per_a = v.gain_m_per_a;
  t.rest_position_m = v.rest_position_m;
  t.natural_frequency_hz = v.natural_frequency_hz;
  t.damping_ratio = v.damping_ratio;
  t.magnetic_lag_s = v.magnetic_lag_s;
  t.width_a = v.width_a;
  t.delay_s = v.delay_s;
  return t;
}

ValveTimeOptimalParams identified_time_optimal(const IdentifiedValve& v, double period_s) {
  ValveTimeOptimalParams t = time_optimal_on(v);
  // No spool of this valve moves faster than g·I_max·ω0 (a spring–mass from rest under a force
  // step F moves at most at F/(m·ω0)): a reference further than that in one sample has jumped.
  t.trigger_m = v.gain_m_per_a * v.current_max_a * 2.0 * std::numbers::pi * v.natural_frequency_hz * period_s;
  // Land on the target: the model's spool runs open loop through the move (not the predictor's,
  // which lags the spool by the LVDT's filter), so its stop is the spool's to tens of µm.
  t.margin_m = 0.0;
  t.horizon_samples = 200;
  return t;
}

// ValveLaw's hook (valve_law.hpp): while a move runs, its current replaces the linear law's, the
// integrator holds and the dither's phase runs on; on the hand-back the reference filter rests on
// the target, so the linear law starts from the hold current the prediction assumed.
// Called by update() only when the step is enabled.
bool ValveLaw::time_optimal_move(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed) noexcept {
  const ValveLawParams& p = params_;
  const double move = time_optimal_.update(reference_m, ref_started_ ? ref_position_ : reference_m, predicted);
  if (time_optimal_.handed_back()) {
    ref_position_ = time_optimal_.target_m();
    ref_velocity_ = ref_acceleration_ = 0.0;
    ref_started_ = true;
  }
  if (std::isnan(move)) return false;
  (void)dither(elapsed);
  error_ = time_optimal_.target_m() - predicted.position_m;
  current_ = move;
  // The current sits at a limit while the move drives or brakes: the law chose it, but it is the
  // limit all the same, and ControlLaw::saturated() (what the current_saturated fault counts) is
  // the command at its limit.
  saturated_ = move <= 0.0 || move >= p.max_current_a;
  if (saturated_) ++saturation_count_;
  integrated_ = false;
  time_optimal_.commanded(current_);
  return true;
}

}  // namespace hsa::control
