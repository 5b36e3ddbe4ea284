#include "daemon/hsad/startup_check.hpp"

#include <array>
#include <optional>
#include <utility>

#include "daemon/axis/axis_loop.hpp"
#include "daemon/axis/axis_signals.hpp"
#include "daemon/hsad/axis_setup.hpp"

namespace hsa::daemon {
namespace {

// Signals on scratch slots: the loop's constructor checks what it is given, not what the slots
// hold, and nothing here runs a cycle.
struct ScratchSignals {
  std::array<io::ChannelSlot, 7> slots{};
  AxisSignals of(const AxisBindings& b) {
    std::optional<io::AnalogInput> spool;
    if (b.spool) spool.emplace(slots[3], b.spool->params);
    std::optional<io::DigitalInput> estop;
    if (b.estop) estop.emplace(slots[6], b.estop->params);
    return AxisSignals{io::AnalogInput(slots[0], b.position.params), io::AnalogInput(slots[1], b.pressure_a.params),
                       io::AnalogInput(slots[2], b.pressure_b.params), std::move(spool),
                       io::AnalogOutput(slots[4], b.valve_command.params),
                       io::DigitalOutput(slots[5], b.valve_enable.params), std::move(estop)};
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
