#include "sim/proportional_valve.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::sim {

namespace {

// 25 us keeps the explicit part of the spool update accurate: omega0 h = 0.008 at 50 Hz, and the
// symplectic Euler period error (omega0 h)^2 / 24 is below 1e-5. Damping is implicit and the lag
// exact, so neither limits the substep.
constexpr double kMaxSubstep = 25e-6;

}  // namespace

ProportionalValve::ProportionalValve(const ProportionalValveParameters& parameters, double step_s)
    : p_(parameters), step_s_(step_s) {
  if (!(step_s > 0.0) || step_s > p_.current_delay_s) {
    throw std::invalid_argument("ProportionalValve: step_s must be in (0, current_delay_s]");
  }
  if (!(p_.moving_mass_kg > 0.0) || !(p_.natural_frequency_hz > 0.0) ||
      !(p_.magnetic_lag_s > 0.0) || !(p_.force_constant_n_per_a > 0.0) ||
      !(p_.stroke_min_m < 0.0) || !(p_.stroke_max_m > 0.0) || !(p_.opening_span_m > 0.0) ||
      p_.damping_ratio < 0.0 || p_.coulomb_friction_n < 0.0 || p_.hysteresis_width_a < 0.0 ||
      p_.current_error_max_a < 0.0 || !(p_.current_max_a > 0.0)) {
    throw std::invalid_argument("ProportionalValve: parameter out of range");
  }

  substeps_ = static_cast<int>(std::ceil(step_s_ / kMaxSubstep));
  substep_s_ = step_s_ / substeps_;
  const double omega0 = 2.0 * std::numbers::pi * p_.natural_frequency_hz;
  stiffness_ = p_.moving_mass_kg * omega0 * omega0;
  damping_ = 2.0 * p_.damping_ratio * p_.moving_mass_kg * omega0;
  lag_gain_ = -std::expm1(-substep_s_ / p_.magnetic_lag_s);

  const auto delay_steps = std::max<long>(1, std::lround(p_.current_delay_s / step_s_));
  reference_delay_.assign(static_cast<std::size_t>(delay_steps), 0.0);
  current_error_ = std::uniform_real_distribution<double>(-p_.current_error_max_a,
                                                          p_.current_error_max_a);
  reset(p_.stroke_min_m);
}

double ProportionalValve::hold_current(double spool_position_m) const {
  const double x = std::clamp(spool_position_m, p_.stroke_min_m, p_.stroke_max_m);
  if (x <= p_.stroke_min_m) {
    return 0.0;  // the rest stop needs no force
  }
  const double c = stiffness_ * (x - p_.stroke_min_m) / p_.force_constant_n_per_a;
  return std::min(c + 0.5 * p_.hysteresis_width_a, p_.current_max_a);
}

void ProportionalValve::reset(double spool_position_m) {
  x_ = std::clamp(spool_position_m, p_.stroke_min_m, p_.stroke_max_m);
  v_ = 0.0;
  c_ = stiffness_ * (x_ - p_.stroke_min_m) / p_.force_constant_n_per_a;
  play_ = c_;
  current_ = hold_current(x_);
  std::fill(reference_delay_.begin(), reference_delay_.end(), current_);
  delay_head_ = 0;
  rng_.seed(p_.seed);
  current_error_.reset();
  stuck_ = false;
}

double ProportionalValve::opening() const {
  const double full_negative = -p_.opening_span_m;
  if (x_ >= full_negative) return std::min(x_ / p_.opening_span_m, 1.0);
  if (x_ <= p_.fail_safe_closed_m) return 0.0;
  // Closing ramp between full negative opening and the blocked fail-safe zone.
  return -(x_ - p_.fail_safe_closed_m) / (full_negative - p_.fail_safe_closed_m);
}

void ProportionalValve::step(double current_reference_a) {
  // The current measured at the end of the previous step is the one flowing during this step.
  // The dead band only moves when the current leaves [play, play + w], so reversals smaller than
  // w leave the force unchanged (eq 6).
  play_ = std::clamp(play_, current_ - p_.hysteresis_width_a, current_);

  for (int i = 0; i < substeps_; ++i) {
    c_ += lag_gain_ * (play_ - c_);
    if (!stuck_) {
      advance_spool(substep_s_);
    }
  }

  // Eq 1: push this step's reference, read the one that reaches the solenoid at the end of it.
  // The reference is held over each step, so after this call the oldest entry, given
  // delay_steps - 1 calls ago, is the one that entered tau ago.
  reference_delay_[delay_head_] = std::clamp(current_reference_a, 0.0, p_.current_max_a);
  delay_head_ = (delay_head_ + 1) % reference_delay_.size();
  const double delayed = reference_delay_[delay_head_];
  // The amplifier drives one way only: the error cannot make the current negative.
  current_ = std::max(0.0, delayed + current_error_(rng_));
}

void ProportionalValve::advance_spool(double h) {
  const double m = p_.moving_mass_kg;
  const double fc = p_.coulomb_friction_n;
  const double drive = p_.force_constant_n_per_a * c_ - stiffness_ * (x_ - p_.stroke_min_m);

  // Pressed against a stop by the net force: stay there (the stop takes the force).
  if ((x_ >= p_.stroke_max_m && drive >= 0.0 && v_ >= 0.0) ||
      (x_ <= p_.stroke_min_m && drive <= 0.0 && v_ <= 0.0)) {
    v_ = 0.0;
    return;
  }
  // At rest, static friction holds as long as it can.
  if (v_ == 0.0 && std::abs(drive) <= fc) {
    return;
  }

  // Friction opposes the motion, or the motion about to start. Damping is implicit, so any
  // damping ratio is stable; position uses the new velocity (symplectic Euler), which keeps the
  // undamped oscillation from gaining energy.
  const double direction = v_ != 0.0 ? std::copysign(1.0, v_) : std::copysign(1.0, drive);
  double v_new = (v_ + h * (drive - fc * direction) / m) / (1.0 + h * damping_ / m);
  if (v_new * v_ < 0.0 && std::abs(drive) <= fc) {
    v_new = 0.0;  // the spool reverses within the substep but static friction can hold it: stick
  }
  v_ = v_new;
  x_ += h * v_;

  // Hard stops: no rebound, the stop absorbs the impact.
  if (x_ > p_.stroke_max_m) {
    x_ = p_.stroke_max_m;
    v_ = 0.0;
  } else if (x_ < p_.stroke_min_m) {
    x_ = p_.stroke_min_m;
    v_ = 0.0;
  }
}

}  // namespace hsa::sim
