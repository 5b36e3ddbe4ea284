#include "control/cascade.hpp"

#include <cmath>
#include <stdexcept>

namespace hsa::control {

Cascade::Cascade(const CascadeParams& params)
    : params_(params),
      pi_(params.cylinder),
      predictor_(params.predictor, params.valve.period_s),
      law_(params.valve) {
  if (params.valve_ticks_per_cylinder_tick == 0)
    throw std::invalid_argument("Cascade: valve ticks per cylinder tick must be >= 1");
  if (!(params.spool_at_full_opening_m > 0.0))
    throw std::invalid_argument("Cascade: spool position at full opening must be > 0");
  const double expected = params.valve.period_s * params.valve_ticks_per_cylinder_tick;
  if (std::abs(params.cylinder.period_s - expected) > 1e-9 * expected)
    throw std::invalid_argument(
        "Cascade: the PI period must equal the valve period times the ticks per cylinder tick");
}

void Cascade::activate(double rod_position_m, double spool_position_m, double current_opening) {
  pi_.activate(rod_position_m, current_opening);
  predictor_.reset(spool_position_m);
  law_.reset();
  anchored_ = false;
}

void Cascade::set_cylinder_gains(double kp, double ki) {
  pi_.set_gains(kp, ki);  // throws before anything changed
  params_.cylinder.kp = kp;
  params_.cylinder.ki = ki;
}

CascadeOutput Cascade::tick(const CascadeInputs& in) {
  return tick(in, anchored_ ? last_tick_ + 1 : 0);
}

CascadeOutput Cascade::tick(const CascadeInputs& in, std::uint64_t base_tick) {
  CascadeOutput out;
  std::uint64_t elapsed = 1;   // valve periods since the last tick
  std::uint64_t pi_periods = 1;
  if (!anchored_) {
    anchored_ = true;
    anchor_tick_ = base_tick;
    last_tick_ = base_tick;
    last_window_ = 0;
    out.cylinder_ticked = true;
  } else {
    const std::uint64_t k = base_tick > last_tick_ ? base_tick : last_tick_ + 1;
    elapsed = k - last_tick_;
    last_tick_ = k;
    const std::uint64_t window = (k - anchor_tick_) / params_.valve_ticks_per_cylinder_tick;
    out.cylinder_ticked = window != last_window_;
    pi_periods = window - last_window_;
    last_window_ = window;
  }
  if (out.cylinder_ticked)
    pi_.update(in.rod_setpoint_m, in.rod_position_m, in.rod_velocity_ff_m_s, pi_periods);

  out.opening = pi_.output();
  out.spool_reference_m = out.opening * params_.spool_at_full_opening_m;
  if (params_.drive == ValveDrive::direct) {
    out.command = out.opening;
  } else {
    out.command = law_.update(out.spool_reference_m, predictor_.update(in.spool_position_m, elapsed), elapsed);
  }
  return out;
}

}  // namespace hsa::control
