// The states and control modes of one axis, as the supervisor's state machine knows them.
//
//   INIT ──first update──▶ DISABLED ◀──disable── ENABLED
//     │                       │  ▲ ──enable──────▶  │
//     │                       │  └──reset (cause gone)── FAULT ◀── any fault ──┘
//     └── fault ──────────────┴────────────────────▶ FAULT
//   any state ── e-stop input ──▶ ESTOP ──reset (released, nothing else present)──▶ DISABLED
//
// Only ENABLED drives the valve; every other state holds the valve at its safe command with the
// amplifier enable off.
#pragma once

#include <cstdint>
#include <string_view>

namespace hsa::daemon {

enum class AxisState : std::uint8_t {
  init,      // before the first update: inputs not judged yet
  disabled,  // healthy, valve safe, waiting for enable
  enabled,   // loops running, valve enabled
  fault,     // latched fault, valve safe, waiting for reset
  estop,     // e-stop asserted (or its input unreadable), valve safe
};

// What the operator's setpoint means while ENABLED.
enum class ControlMode : std::uint8_t {
  position,   // setpoint = rod position (m); the cascade closes the loops
  open_loop,  // setpoint = valve opening in [-1, 1]; no position loop
};

std::string_view to_string(AxisState state) noexcept;
std::string_view to_string(ControlMode mode) noexcept;

}  // namespace hsa::daemon
