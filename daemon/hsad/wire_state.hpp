// The axis state as the LCM messages carry it (status_t.STATE_*), for telemetry and status alike.
#pragma once

#include "daemon/lcm_bridge/rt_messages.hpp"
#include "daemon/supervisor/axis_state.hpp"

namespace hsa::daemon {

[[nodiscard]] constexpr MsgAxisState to_wire(AxisState s) noexcept {
  switch (s) {
    case AxisState::init: return MsgAxisState::init;
    case AxisState::disabled: return MsgAxisState::disabled;
    case AxisState::enabled: return MsgAxisState::enabled;
    case AxisState::fault: return MsgAxisState::fault;
    case AxisState::estop: return MsgAxisState::estop;
  }
  return MsgAxisState::fault;
}

}  // namespace hsa::daemon
