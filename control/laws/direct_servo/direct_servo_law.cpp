#include "control/laws/direct_servo/direct_servo_law.hpp"

#include <cmath>
#include <utility>

namespace hsa::control {

namespace {

CascadeParams direct_cascade(const PiParams& pi, std::uint32_t ticks_per_cylinder_tick) {
  CascadeParams c;
  c.drive = ValveDrive::direct;
  c.cylinder = pi;
  c.valve_ticks_per_cylinder_tick = ticks_per_cylinder_tick;
  c.valve.period_s = pi.period_s / ticks_per_cylinder_tick;
  return c;
}

}  // namespace

DirectServoLaw::DirectServoLaw(const PiParams& pi, std::uint32_t ticks_per_cylinder_tick, const GainBounds& bounds,
                               std::shared_ptr<const GainGate> gate)
    : PiCascadeLaw(direct_cascade(pi, ticks_per_cylinder_tick), bounds, std::move(gate)) {}

std::unique_ptr<ControlLaw> DirectServoLaw::from_settings(const LawSettings& axis, const LawTiming& timing) {
  GainBounds bounds;
  std::shared_ptr<const GainGate> gate;
  const PiParams pi = read_pi(axis, timing, bounds, gate);
  return std::make_unique<DirectServoLaw>(pi, timing.ticks_per_cylinder_tick, bounds, std::move(gate));
}

std::unique_ptr<ControlLaw> DirectServoLaw::clone() const {
  return std::make_unique<DirectServoLaw>(cascade_.params().cylinder, cascade_.params().valve_ticks_per_cylinder_tick,
                                          gain_bounds(), gate());
}

double DirectServoLaw::null_command() const noexcept { return 0.0; }

std::string DirectServoLaw::safe_command_refusal(double command, double band) const {
  if (std::abs(command) <= band) return "";
  return "a finite number in [" + format_setting(-band) + ", " + format_setting(band) + "]";
}

std::string DirectServoLaw::describe() const { return describe_pi(); }
}  // namespace hsa::control
