// Where each signal of an axis comes from: a driver instance, one of its channels, and the
// limits or inversion the I/O layer applies (hsa::io::bind_* takes exactly these). The configuration checks
// that `driver` names a configured [[drivers]] entry; whether the channel exists and has the
// right kind is checked at bind time, when the driver has declared its channels.
#pragma once

#include <optional>
#include <string>

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

struct AxisSignalConfig {
  AnalogInputConfig position;    // encoder input: rod position, m
  AnalogInputConfig pressure_a;  // analog input: chamber A, Pa
  AnalogInputConfig pressure_b;  // analog input: chamber B, Pa
  // Analog input: spool position, m. Always present with a proportional drive (the valve loop
  // needs it); optional with a direct drive, where it is only reported.
  std::optional<AnalogInputConfig> spool;
  AnalogOutputConfig valve_command;  // analog output: opening (direct) or current ref, A (proportional)
  DigitalOutputConfig valve_enable;  // digital output: valve amplifier enable
  // Digital input, true while the e-stop is pressed (after `invert`). Wire it so that a broken
  // loop reads as pressed: an active-low loop (1 = closed) needs invert = true.
  std::optional<DigitalInputConfig> estop;
};

}  // namespace hsa::daemon
