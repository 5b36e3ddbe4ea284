#include "control/cascade.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::control {

Cascade::Cascade(const CascadeParams& params)
    : ticks_per_cylinder_tick_(params.valve_ticks_per_cylinder_tick),
      params_(params),
      pi_(params.cylinder),
      predictor_(params.predictor, params.valve.period_s),
      law_(params.valve) {
  if (params.drive == ValveDrive::proportional && params.valve.model_predictor.enabled) {
    model_predictor_.emplace(params.valve.model_predictor, params.valve.period_s);
    model_predicted_ = true;
  }
  if (params.drive == ValveDrive::proportional && params.valve.predictive.enabled) {
    // The PI's opening, and with it the spool reference, is held over its period: the law takes
    // the line through its steps (ValvePredictiveParams::reference_window_samples).
    ValvePredictiveParams predictive = params.valve.predictive;
    predictive.reference_window_samples = static_cast<int>(
        std::min<std::uint32_t>(params.valve_ticks_per_cylinder_tick, ValvePredictiveLaw::kMaxReferenceWindow));
    predictive_.emplace(predictive);
    predictive_law_ = true;
  }
  if (params.valve_ticks_per_cylinder_tick == 0)
    throw std::invalid_argument("Cascade: valve ticks per cylinder tick must be >= 1");
  if (!(params.spool_at_full_opening_m > 0.0))
    throw std::invalid_argument("Cascade: spool position at full opening must be > 0");
  const double expected = params.valve.period_s * params.valve_ticks_per_cylinder_tick;
  if (std::abs(params.cylinder.period_s - expected) > 1e-9 * expected)
    throw std::invalid_argument(
        "Cascade: the PI period must equal the valve period times the ticks per cylinder tick");
}

void Cascade::activate(double rod_position_m, double spool_position_m, double current_opening) noexcept {
  pi_.activate(rod_position_m, current_opening);
  predictor_.reset(spool_position_m);
  if (model_predictor_) model_predictor_->reset(spool_position_m);
  if (predictive_) predictive_->reset(spool_position_m, spool_position_m);
  law_.reset();
  anchored_ = false;
}

bool Cascade::set_cylinder_gains(double kp, double ki) noexcept {
  if (!pi_.set_gains(kp, ki)) return false;  // refused: nothing changed
  params_.cylinder.kp = kp;
  params_.cylinder.ki = ki;
  return true;
}

std::uint64_t Cascade::advance_to(std::uint64_t base_tick) noexcept {
  if (!anchored_) {
    anchored_ = true;
    last_tick_ = base_tick;
    window_ = phase_ = last_window_ = 0;
    return 1;
  }
  const std::uint64_t k = base_tick > last_tick_ ? base_tick : last_tick_ + 1;
  const std::uint64_t elapsed = k - last_tick_;
  last_tick_ = k;
  const std::uint64_t n = ticks_per_cylinder_tick_;
  phase_ += elapsed;
  if (phase_ >= 2 * n) {  // a jump over whole PI periods: rare, divide
    window_ += phase_ / n;
    phase_ %= n;
  } else if (phase_ >= n) {
    ++window_;
    phase_ -= n;
  }
  return elapsed;
}

LawOutput Cascade::valve_stage(double opening, double spool_position_m, std::uint64_t elapsed) noexcept {
  LawOutput out;
  out.opening = opening;
  out.spool_reference_m = opening * params_.spool_at_full_opening_m;
  if (params_.drive == ValveDrive::direct) {
    out.command = opening;
  } else if (predictive_law_) [[unlikely]] {
    out.command = predictive_->update(out.spool_reference_m, spool_position_m, elapsed);
  } else if (model_predicted_) [[unlikely]] {
    out.command = model_predicted_law(out.spool_reference_m, spool_position_m, elapsed);
  } else {
    out.command = law_.update(out.spool_reference_m, predictor_.update(spool_position_m, elapsed), elapsed);
  }
  return out;
}

double Cascade::model_predicted_law(double reference_m, double spool_position_m, std::uint64_t elapsed) noexcept {
  ValveModelPredictor& predictor = *model_predictor_;
  if (elapsed > 1) [[unlikely]] {
    // The missed periods: the drive held the last current, the LVDT reads as now.
    const std::uint64_t missed = std::min<std::uint64_t>(elapsed - 1, StatePredictor::kMaxCatchUp);
    const double held = law_.current();
    for (std::uint64_t i = 0; i < missed; ++i) {
      (void)predictor.update(spool_position_m);
      predictor.commanded(held);
    }
  }
  const double current = law_.update(reference_m, predictor.update(spool_position_m), elapsed);
  predictor.commanded(current);
  return current;
}

void Cascade::run_cylinder(const LawInputs& in, std::uint64_t periods) noexcept {
  pi_.update(in.rod_setpoint_m, in.rod_position_m,
             SetpointMotion{in.rod_velocity_ff_m_s, in.rod_accel_ff_m_s2, in.rod_jerk_ff_m_s3, in.rod_setpoint_planned},
             periods);
}

LawOutput Cascade::tick(const LawInputs& in, std::uint64_t base_tick) noexcept {
  // The next tick after a tick(), nine in ten of them without the PI: what advance_to() and the
  // general path below make of it when one valve period elapsed and the PI is not behind (phase_
  // is below N, so one period moves it into the next window at most).
  if (anchored_ && base_tick == last_tick_ + 1 && window_ == last_window_) [[likely]] {
    last_tick_ = base_tick;
    const bool cylinder_ticked = ++phase_ == ticks_per_cylinder_tick_;
    if (cylinder_ticked) {
      phase_ = 0;
      last_window_ = ++window_;
      run_cylinder(in, 1);
    }
    LawOutput out = valve_stage(pi_.output(), in.spool_position_m, 1);
    out.cylinder_ticked = cylinder_ticked;
    return out;
  }
  return tick_after_gap(in, base_tick);
}

LawOutput Cascade::tick_after_gap(const LawInputs& in, std::uint64_t base_tick) noexcept {
  const bool first = !anchored_;
  const std::uint64_t elapsed = advance_to(base_tick);
  bool cylinder_ticked = true;
  std::uint64_t pi_periods = 1;
  if (!first) {
    cylinder_ticked = window_ != last_window_;
    pi_periods = window_ - last_window_;
    last_window_ = window_;
  }
  if (cylinder_ticked) run_cylinder(in, pi_periods);

  LawOutput out = valve_stage(pi_.output(), in.spool_position_m, elapsed);
  out.cylinder_ticked = cylinder_ticked;
  return out;
}

LawOutput Cascade::open_loop_tick(double opening, double spool_position_m, std::uint64_t base_tick) noexcept {
  return valve_stage(opening, spool_position_m, advance_to(base_tick));
}

}  // namespace hsa::control
