#include "daemon/hsad/startup_check.hpp"

#include <array>

#include "daemon/axis/axis_loop.hpp"
#include "daemon/axis/axis_signals.hpp"
#include "daemon/hsad/axis_setup.hpp"

namespace hsa::daemon {
namespace {

// Signals on scratch slots: the loop's constructor checks what it is given, not what the slots
// hold, and nothing here runs a cycle.
struct ScratchSignals {
  // One per input of the table, then the valve command and enable.
  std::array<io::ChannelSlot, kAxisInputCount + 2> slots{};
  AxisSignals of(const AxisBindings& b) {
    AxisSignals s{.valve_command = io::AnalogOutput(slots[kAxisInputCount], b.valve_command.params),
                  .valve_enable = io::DigitalOutput(slots[kAxisInputCount + 1], b.valve_enable.params)};
#define HSA_SCRATCH_INPUT(signal, name, kind, presence, unreadable) \
  if (const auto* x = present(b.signal)) s.signal.emplace(slots[static_cast<std::size_t>(AxisInput::signal)], x->params);
    HSA_AXIS_INPUTS(HSA_SCRATCH_INPUT)
#undef HSA_SCRATCH_INPUT
    return s;
  }
};

}  // namespace

void check_axes(const DaemonConfig& config, const std::vector<PlannedDriver>& drivers) {
  std::vector<io::DeclaredDriver> declared;
  for (const PlannedDriver& d : drivers) declared.push_back(d.declared());
  for (const AxisConfig& a : config.axes) {
    const AxisParams params = axis_params(a, config.realtime);
    check_axis_signals(a.name, params.bindings, declared);
    ScratchSignals scratch;
    const AxisLoop loop(params, scratch.of(params.bindings));
  }
}

}  // namespace hsa::daemon
