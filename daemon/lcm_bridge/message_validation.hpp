// Validation of incoming setpoints and commands: the gate between the network and the loops. It
// produces the supervisor's own types (SetpointInput, AxisCommand), so the wire's constants are
// mapped here and nowhere else.
//
// Pure functions (no I/O, no state), so every rule is testable without LCM running. A message that
// fails any rule is rejected as a whole, with one reason, and never reaches the RT thread: a NaN
// must not get into an integrator, and a half-applied command is worse than none. Only the fields
// a message uses are checked (a command's gains are ignored unless it is GAINS), and fields it
// does not use are zeroed so that nothing unchecked crosses the ring.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string_view>

#include "daemon/axis/axis_port.hpp"
#include "daemon/axis/reject_reason.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/operator_input.hpp"
#include "msgs/decode_exact.hpp"
#include "hsa/command_t.hpp"
#include "hsa/setpoint_t.hpp"

namespace hsa::daemon {

// A validated message, or why not. `msg` is meaningful only when ok().
template <typename T>
struct Validated {
  RejectReason reason = RejectReason::none;
  T msg{};

  [[nodiscard]] bool ok() const { return reason == RejectReason::none; }
};

[[nodiscard]] Validated<SetpointInput> validate_setpoint(const hsa::setpoint_t& in, const AxisLimits& limits);
// ACQUIRE and RELEASE are the bridge's own (command_lease.hpp): unknown here.
[[nodiscard]] Validated<AxisCommand> validate_command(const hsa::command_t& in);

// decode_exact (msgs/decode_exact.hpp): the one way hsa decodes bytes from the network.
using msgs::decode_exact;

}  // namespace hsa::daemon
