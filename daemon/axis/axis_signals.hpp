// The bound signals of one axis, and the function that binds them from AxisBindings.
//
// Binding runs at start-up on a normal thread and throws io::BindingError on any mismatch (a
// missing driver, a missing channel, a wrong channel kind), naming the axis's signal; the loop
// then only reads and writes the bound slots, which is real-time safe.
#pragma once

#include <optional>
#include <span>

#include "daemon/axis/axis_params.hpp"
#include "drivers/driver_handle.hpp"
#include "drivers/signal_binding.hpp"

namespace hsa::daemon {

struct AxisSignals {
  io::AnalogInput position;
  io::AnalogInput pressure_a;
  io::AnalogInput pressure_b;
  std::optional<io::AnalogInput> spool;
  io::AnalogOutput valve_command;
  io::DigitalOutput valve_enable;
  std::optional<io::DigitalInput> estop;
};

// Looks each binding's driver up by name among `drivers` (configured handles).
AxisSignals bind_axis_signals(std::string_view axis, const AxisBindings& bindings,
                              std::span<io::DriverHandle* const> drivers);

}  // namespace hsa::daemon
