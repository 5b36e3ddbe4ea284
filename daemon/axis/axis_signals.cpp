#include "daemon/axis/axis_signals.hpp"

#include <string>
#include <vector>

namespace hsa::daemon {
namespace {

std::string signal_name(std::string_view axis, std::string_view what) {
  return std::string(axis) + "." + std::string(what);
}

template <class Params>
[[noreturn]] void no_driver(std::string_view axis, std::string_view what, const Binding<Params>& binding) {
  const std::string signal = signal_name(axis, what);
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

template <class Params>
void check_analog(std::string_view axis, std::string_view what, const Binding<Params>& x, io::ChannelKind kind,
                  std::span<const io::DeclaredDriver> drivers) {
  (void)io::check_binding(signal_name(axis, what), declared_for(axis, what, x, drivers), x.channel, kind,
                          &x.params.low_limit, &x.params.high_limit);
}

template <class Params>
void check_digital(std::string_view axis, std::string_view what, const Binding<Params>& x, io::ChannelKind kind,
                   std::span<const io::DeclaredDriver> drivers) {
  (void)io::check_binding(signal_name(axis, what), declared_for(axis, what, x, drivers), x.channel, kind);
}

void check_input(std::string_view axis, AxisInput input, const Binding<io::AnalogInputParams>& x,
                 std::span<const io::DeclaredDriver> drivers) {
  check_analog(axis, info(input).key, x, channel_kind(info(input).kind), drivers);
}

void check_input(std::string_view axis, AxisInput input, const Binding<io::DigitalInputParams>& x,
                 std::span<const io::DeclaredDriver> drivers) {
  check_digital(axis, info(input).key, x, channel_kind(info(input).kind), drivers);
}

io::AnalogInput bind_input(std::string_view axis, AxisInput input, const Binding<io::AnalogInputParams>& x,
                           std::span<io::DriverHandle* const> drivers) {
  const std::string_view what = info(input).key;
  io::DriverHandle& d = driver_for(axis, what, x, drivers);
  return info(input).kind == InputKind::encoder ? io::bind_encoder_input(signal_name(axis, what), d, x.channel, x.params)
                                                : io::bind_analog_input(signal_name(axis, what), d, x.channel, x.params);
}

io::DigitalInput bind_input(std::string_view axis, AxisInput input, const Binding<io::DigitalInputParams>& x,
                            std::span<io::DriverHandle* const> drivers) {
  const std::string_view what = info(input).key;
  return io::bind_digital_input(signal_name(axis, what), driver_for(axis, what, x, drivers), x.channel, x.params);
}

}  // namespace

void check_axis_signals(std::string_view axis, const AxisBindings& b, std::span<const io::DeclaredDriver> drivers) {
  // bind_axis_signals's order: the inputs in the table's order, then the outputs.
#define HSA_CHECK_INPUT(signal, name, kind, presence, unreadable) \
  if (const auto* x = present(b.signal)) check_input(axis, AxisInput::signal, *x, drivers);
  HSA_AXIS_INPUTS(HSA_CHECK_INPUT)
#undef HSA_CHECK_INPUT
  check_analog(axis, "valve_command", b.valve_command, io::ChannelKind::analog_output, drivers);
  check_digital(axis, "valve_enable", b.valve_enable, io::ChannelKind::digital_output, drivers);
}

AxisSignals bind_axis_signals(std::string_view axis, const AxisBindings& b,
                              std::span<io::DriverHandle* const> drivers) {
  // The checks first, so that the start refuses exactly as `hsad --check-config` does.
  std::vector<io::DeclaredDriver> declared;
  for (const io::DriverHandle* d : drivers) {
    if (d != nullptr) declared.push_back({d->name(), d->plugin().descriptor().name, d->channels()});
  }
  check_axis_signals(axis, b, declared);
  AxisSignals s{
      .valve_command = io::bind_analog_output(signal_name(axis, "valve_command"),
                                              driver_for(axis, "valve_command", b.valve_command, drivers),
                                              b.valve_command.channel, b.valve_command.params),
      .valve_enable = io::bind_digital_output(signal_name(axis, "valve_enable"),
                                              driver_for(axis, "valve_enable", b.valve_enable, drivers),
                                              b.valve_enable.channel, b.valve_enable.params),
  };
#define HSA_BIND_INPUT(signal, name, kind, presence, unreadable) \
  if (const auto* x = present(b.signal)) s.signal = bind_input(axis, AxisInput::signal, *x, drivers);
  HSA_AXIS_INPUTS(HSA_BIND_INPUT)
#undef HSA_BIND_INPUT
  return s;
}

}  // namespace hsa::daemon
