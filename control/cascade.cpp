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
  tick_in_cycle_ = 0;
}

void Cascade::set_cylinder_gains(double kp, double ki) {
  pi_.set_gains(kp, ki);  // throws before anything changed
  params_.cylinder.kp = kp;
  params_.cylinder.ki = ki;
}

CascadeOutput Cascade::tick(const CascadeInputs& in) {
  CascadeOutput out;
  out.cylinder_ticked = tick_in_cycle_ == 0;
  if (out.cylinder_ticked) pi_.update(in.rod_setpoint_m, in.rod_position_m, in.rod_velocity_ff_m_s);
  if (++tick_in_cycle_ == params_.valve_ticks_per_cylinder_tick) tick_in_cycle_ = 0;

  out.opening = pi_.output();
  out.spool_reference_m = out.opening * params_.spool_at_full_opening_m;
  if (params_.drive == ValveDrive::direct) {
    out.command = out.opening;
  } else {
    out.command = law_.update(out.spool_reference_m, predictor_.update(in.spool_position_m));
  }
  return out;
}

}  // namespace hsa::control
