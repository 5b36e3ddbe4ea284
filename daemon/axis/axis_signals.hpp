// The bound signals of one axis, and the function that binds them from AxisBindings.
//
// Binding runs at start-up on a normal thread and throws io::BindingError on any mismatch (a
// missing driver, a missing channel, a wrong channel kind), naming the axis's signal; the same
// checks run without any device on the channels a driver's settings declare; the loop
// then only reads and writes the bound slots, which is real-time safe.
#pragma once

#include <optional>
#include <span>

#include "daemon/axis/axis_params.hpp"
#include "drivers/driver_handle.hpp"
#include "drivers/signal_binding.hpp"

namespace hsa::daemon {

struct AxisSignals {
  // One per input of the table (axis_inputs.hpp), absent when unbound; AxisLoop refuses signals
  // without an input the table or the law requires.
#define HSA_BOUND_INPUT(signal, name, kind, presence, unreadable) std::optional<BoundInput<InputKind::kind>> signal{};
  HSA_AXIS_INPUTS(HSA_BOUND_INPUT)
#undef HSA_BOUND_INPUT
  io::AnalogOutput valve_command;
  io::DigitalOutput valve_enable;
};

// Looks each binding's driver up by name among `drivers` (configured handles). Refuses with the
// text check_axis_signals gives for the same channels.
AxisSignals bind_axis_signals(std::string_view axis, const AxisBindings& bindings,
                              std::span<io::DriverHandle* const> drivers);

// The checks of bind_axis_signals, in its order, against the channels the drivers declare or would
// declare (`hsad --check-config`: their plans). Throws the io::BindingError the bind would.
void check_axis_signals(std::string_view axis, const AxisBindings& bindings,
                        std::span<const io::DeclaredDriver> drivers);

}  // namespace hsa::daemon
