// What reaches one axis's cycle from outside the loop: the operator's latest setpoint and command
// (the RT thread fills them from the axis's port, daemon/axis/axis_port.hpp) and the executive's
// health inputs.
//
// Both operator fields are "latest value with a sequence number", not events: the RT thread may
// hand the same struct to every cycle, and the axis acts on a setpoint or a command once, when its
// `seq` changes. Setpoint silence is measured on the daemon's clock from the cycle in which a new
// seq was first seen, so the sender's clock (utime) never has to agree with ours.
#pragma once

#include <cstdint>
#include <type_traits>

#include "daemon/supervisor/command.hpp"

namespace hsa::daemon {

struct SetpointInput {
  std::uint64_t seq = 0;   // 0 = none received yet; a new value = a new setpoint
  std::int64_t utime = 0;  // sender's timestamp (µs), passed through to telemetry
  // Position mode: rod position (m). Open-loop mode: valve opening in [-1, 1].
  double target = 0.0;
  double velocity_m_s = 0.0;  // velocity feed-forward (0 if none): PiParams::velocity_feedforward
};

struct AxisInputsFromOperator {
  SetpointInput setpoint;
  AxisCommand command;
};

// Health the RT executive knows and the axis cannot see from its signals.
struct ExecutiveInputs {
  std::uint32_t overrun_streak = 0;  // consecutive overrunning cycles, 0 after an on-time one
  bool driver_error = false;         // a driver of this axis failed its read or write
  // The executive has stopped and this is the shutdown's last cycle, which only disables: the
  // pause before it is not blind time.
  bool final_cycle = false;
};

// Their parts cross the port's rings by value.
static_assert(std::is_trivially_copyable_v<AxisInputsFromOperator>);

}  // namespace hsa::daemon
