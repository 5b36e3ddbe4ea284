// Everything one axis needs to be built: its name, its signal bindings, its safety thresholds,
// its safe command and its control law. Plain data in SI units, so the configuration code can fill
// it field by field from its own structs.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "control/control_law.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/axis_supervisor.hpp"
#include "drivers/signal_binding.hpp"

namespace hsa::daemon {

// One signal → one channel of one driver instance, with the framework's scaling.
template <class Params>
struct Binding {
  std::string driver;   // instance name in the configuration, e.g. "rig"
  std::string channel;  // the driver's channel, e.g. "encoder"
  Params params{};
};

struct AxisBindings {
  Binding<io::AnalogInputParams> position{"", "encoder"};
  Binding<io::AnalogInputParams> pressure_a{"", "pressure_a"};
  Binding<io::AnalogInputParams> pressure_b{"", "pressure_b"};
  // Proportional drive only: the spool LVDT the valve loop closes on.
  std::optional<Binding<io::AnalogInputParams>> spool;
  // The valve command: the opening (direct drive) or the current reference (proportional).
  Binding<io::AnalogOutputParams> valve_command{"", "opening_cmd"};
  Binding<io::DigitalOutputParams> valve_enable{"", "valve_enable"};
  // Asserted = pressed, after the binding's inversion (wire active-low loops with invert = true).
  std::optional<Binding<io::DigitalInputParams>> estop;
};

struct AxisParams {
  std::string name = "axis";
  AxisBindings bindings;
  SupervisorParams safety;
  // What the valve command output holds whenever the axis does not drive it: the valve's null
  // (servo-valve opening 0; a proportional valve's de-energized current, where its spring centres
  // the spool in the fail-safe zone).
  double safe_command = 0.0;
  // The configured law; the loop runs its own clone of it.
  std::shared_ptr<const control::ControlLaw> law;
  ControlMode initial_mode = ControlMode::position;
  double area_ratio = 1.0;               // α = annulus/piston area, for p_load = p_A − α·p_B
  double velocity_filter_s = 0.005;      // time constant of the rod velocity estimate
};

}  // namespace hsa::daemon
