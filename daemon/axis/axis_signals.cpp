#include "daemon/axis/axis_signals.hpp"

#include <string>
#include <vector>

namespace hsa::daemon {
namespace {

template <class Params>
[[noreturn]] void no_driver(std::string_view axis, std::string_view what, const Binding<Params>& binding) {
  const std::string signal = std::string(axis) + "." + std::string(what);
  throw io::BindingError(signal, binding.driver, binding.channel,
                         "signal '" + signal + "': no driver named '" + binding.driver + "'");
}

template <class Params>
io::DriverHandle& driver_for(std::string_view axis, std::string_view what,
                             const Binding<Params>& binding,
                             std::span<io::DriverHandle* const> drivers) {
  for (io::DriverHandle* d : drivers) {
    if (d != nullptr && d->name() == binding.driver) return *d;
  }
  no_driver(axis, what, binding);
}

template <class Params>
const io::DeclaredDriver& declared_for(std::string_view axis, std::string_view what, const Binding<Params>& binding,
                                       std::span<const io::DeclaredDriver> drivers) {
  for (const io::DeclaredDriver& d : drivers) {
    if (d.name == binding.driver) return d;
  }
  no_driver(axis, what, binding);
}

}  // namespace

void check_axis_signals(std::string_view axis, const AxisBindings& b, std::span<const io::DeclaredDriver> drivers) {
  const auto name = [&](std::string_view what) { return std::string(axis) + "." + std::string(what); };
  const auto analog = [&](std::string_view what, const auto& x, io::ChannelKind kind) {
    (void)io::check_binding(name(what), declared_for(axis, what, x, drivers), x.channel, kind, &x.params.low_limit,
                            &x.params.high_limit);
  };
  const auto digital = [&](std::string_view what, const auto& x, io::ChannelKind kind) {
    (void)io::check_binding(name(what), declared_for(axis, what, x, drivers), x.channel, kind);
  };
  // bind_axis_signals's order: the optional signals, then the others as AxisSignals lists them.
  if (b.spool) analog("spool", *b.spool, io::ChannelKind::analog_input);
  if (b.estop) digital("estop", *b.estop, io::ChannelKind::digital_input);
  analog("position", b.position, io::ChannelKind::encoder_input);
  analog("pressure_a", b.pressure_a, io::ChannelKind::analog_input);
  analog("pressure_b", b.pressure_b, io::ChannelKind::analog_input);
  analog("valve_command", b.valve_command, io::ChannelKind::analog_output);
  digital("valve_enable", b.valve_enable, io::ChannelKind::digital_output);
}

AxisSignals bind_axis_signals(std::string_view axis, const AxisBindings& b,
                              std::span<io::DriverHandle* const> drivers) {
  // The checks first, so that the start refuses exactly as `hsad --check-config` does.
  std::vector<io::DeclaredDriver> declared;
  for (const io::DriverHandle* d : drivers) {
    if (d != nullptr) declared.push_back({d->name(), d->plugin().descriptor().name, d->channels()});
  }
  check_axis_signals(axis, b, declared);
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
