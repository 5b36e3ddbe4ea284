#include "daemon/axis/axis_signals.hpp"

#include <string>

namespace hsa::daemon {
namespace {

template <class Params>
io::DriverHandle& driver_for(std::string_view axis, std::string_view what,
                             const Binding<Params>& binding,
                             std::span<io::DriverHandle* const> drivers) {
  for (io::DriverHandle* d : drivers) {
    if (d != nullptr && d->name() == binding.driver) return *d;
  }
  const std::string signal = std::string(axis) + "." + std::string(what);
  throw io::BindingError(signal, binding.driver, binding.channel,
                         "signal '" + signal + "': no driver named '" + binding.driver + "'");
}

}  // namespace

AxisSignals bind_axis_signals(std::string_view axis, const AxisBindings& b,
                              std::span<io::DriverHandle* const> drivers) {
  const auto name = [&](std::string_view what) { return std::string(axis) + "." + std::string(what); };
  const auto analog_in = [&](std::string_view what, const Binding<io::AnalogInputParams>& x,
                             bool encoder) {
    io::DriverHandle& d = driver_for(axis, what, x, drivers);
    return encoder ? io::bind_encoder_input(name(what), d, x.channel, x.params)
                   : io::bind_analog_input(name(what), d, x.channel, x.params);
  };

  std::optional<io::AnalogInput> spool;
  if (b.spool) spool = analog_in("spool", *b.spool, false);
  std::optional<io::DigitalInput> estop;
  if (b.estop) {
    estop = io::bind_digital_input(name("estop"), driver_for(axis, "estop", *b.estop, drivers),
                                   b.estop->channel, b.estop->params);
  }
  return AxisSignals{
      analog_in("position", b.position, true),
      analog_in("pressure_a", b.pressure_a, false),
      analog_in("pressure_b", b.pressure_b, false),
      std::move(spool),
      io::bind_analog_output(name("valve_command"),
                             driver_for(axis, "valve_command", b.valve_command, drivers),
                             b.valve_command.channel, b.valve_command.params),
      io::bind_digital_output(name("valve_enable"),
                              driver_for(axis, "valve_enable", b.valve_enable, drivers),
                              b.valve_enable.channel, b.valve_enable.params),
      std::move(estop),
  };
}

}  // namespace hsa::daemon
