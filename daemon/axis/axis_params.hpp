// Everything one axis needs to be built: its name, its signal bindings, its safety thresholds,
// its safe command and its control law. Plain data in SI units, so the configuration code can fill
// it field by field from its own structs.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "control/control_law.hpp"
#include "daemon/supervisor/axis_inputs.hpp"
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
  // One member per input of the table (axis_inputs.hpp); an absent optional input is unbound.
#define HSA_INPUT_BINDING(signal, name, kind, presence, unreadable) \
  InputField<InputPresence::presence, Binding<InputParams<InputKind::kind>>> signal;
  HSA_AXIS_INPUTS(HSA_INPUT_BINDING)
#undef HSA_INPUT_BINDING
  // The valve command: the opening (direct drive) or the current reference (proportional).
  Binding<io::AnalogOutputParams> valve_command{"", "opening_cmd"};
  Binding<io::DigitalOutputParams> valve_enable{"", "valve_enable"};
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
