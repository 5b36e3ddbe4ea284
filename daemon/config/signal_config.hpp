// Where each signal of an axis comes from: a driver instance, one of its channels, and the
// limits or inversion the I/O layer applies (hsa::io::bind_* takes exactly these). The configuration checks
// that `driver` names a configured [[drivers]] entry; whether the channel exists and has the
// right kind is checked at bind time, when the driver has declared its channels.
#pragma once

#include <optional>
#include <string>

#include "daemon/supervisor/axis_inputs.hpp"
#include "drivers/signal_binding.hpp"

namespace hsa::daemon {

template <class Params>
struct SignalConfig {
  std::string driver;   // a DriverConfig::name
  std::string channel;  // a channel that driver declares
  Params params{};
};

using AnalogInputConfig = SignalConfig<io::AnalogInputParams>;  // encoder and analog inputs
using AnalogOutputConfig = SignalConfig<io::AnalogOutputParams>;
using DigitalInputConfig = SignalConfig<io::DigitalInputParams>;
using DigitalOutputConfig = SignalConfig<io::DigitalOutputParams>;

// Digital inputs are true while asserted (after `invert`): wire an e-stop so that a broken loop
// reads as pressed, an active-low loop (1 = closed) with invert = true.
struct AxisSignalConfig {
  // One member per input of the table (axis_inputs.hpp), e.g. position (encoder input, m),
  // pressure_a and pressure_b (Pa), spool (m: present with a law that closes its valve loop on
  // it, optional otherwise, where it is only reported), estop.
#define HSA_INPUT_CONFIG(signal, name, kind, presence, unreadable) \
  InputField<InputPresence::presence, SignalConfig<InputParams<InputKind::kind>>> signal;
  HSA_AXIS_INPUTS(HSA_INPUT_CONFIG)
#undef HSA_INPUT_CONFIG
  AnalogOutputConfig valve_command;  // analog output: opening (direct) or current ref, A (proportional)
  DigitalOutputConfig valve_enable;  // digital output: valve amplifier enable
};

}  // namespace hsa::daemon
