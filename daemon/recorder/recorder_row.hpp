// One row of the flight recorder: what an axis's RT cycle did, written every base tick (the valve
// loop's rate) into the axis's CaptureRing. Plain and trivially copyable, so that writing it is a
// few stores into preallocated memory.
//
// HSA_RECORDER_SIGNALS lists the columns a capture file holds, one vector each: its name in the
// file, its unit and how it is read from a row. The file writer and the docs
// (docs/flight-recorder.md) follow this table; a column added here appears in every new capture.
#pragma once

#include <cstdint>
#include <type_traits>

namespace hsa::daemon {

struct RecorderRow {
  std::uint64_t seq = 0;         // the axis's row count since start: consecutive rows differ by 1
  std::uint64_t tick = 0;        // the cycle's base-tick index (telemetry_t.seq)
  std::uint64_t skipped = 0;     // base ticks the executive skipped before this cycle (overruns):
                                 // tick − previous tick = 1 + skipped
  std::int64_t t_ns = 0;         // the cycle's time on the daemon's clock (from its start)
  double setpoint = 0.0;         // position mode: rod setpoint (m) after hold and soft limits; open loop: opening
  double rod_setpoint_m = 0.0;   // the setpoint the cylinder loop follows now (rate limit, move profile)
  double position_m = 0.0;
  double velocity_m_s = 0.0;
  double following_error_m = 0.0;
  double opening = 0.0;          // valve opening the loops asked for, [-1, 1]
  double command = 0.0;          // what the valve command output holds (opening, or coil current A)
  double spool_m = 0.0;          // proportional drive: LVDT; else 0
  double pressure_a_pa = 0.0;
  double pressure_b_pa = 0.0;
  double integral = 0.0;         // the cylinder PI's integral term (opening)
  std::uint32_t active_faults = 0;  // fault_bit() flags present this cycle
  std::int32_t lateness_ns = 0;  // woke − scheduled of this cycle
  std::int32_t exec_ns = 0;      // the whole RT cycle's execution time (all axes, drivers)
  std::uint8_t state = 0;        // AxisState
  std::uint8_t mode = 0;         // ControlMode
  std::uint8_t valve_enabled = 0;
  std::uint8_t fault_reason = 0;  // FaultReason latched (0: none)
};

static_assert(std::is_trivially_copyable_v<RecorderRow>);

// X(name in the file, unit, expression over `const RecorderRow& r`)
#define HSA_RECORDER_SIGNALS(X)                                        \
  X("seq", "rows", static_cast<double>(r.seq))                         \
  X("tick", "base ticks", static_cast<double>(r.tick))                 \
  X("skipped", "base ticks", static_cast<double>(r.skipped))           \
  X("t_ns", "ns", static_cast<double>(r.t_ns))                         \
  X("setpoint", "m or opening", r.setpoint)                            \
  X("rod_setpoint_m", "m", r.rod_setpoint_m)                           \
  X("position_m", "m", r.position_m)                                   \
  X("velocity_m_s", "m/s", r.velocity_m_s)                             \
  X("following_error_m", "m", r.following_error_m)                     \
  X("valve_opening", "1", r.opening)                                   \
  X("valve_command", "opening or A", r.command)                        \
  X("spool_m", "m", r.spool_m)                                         \
  X("pressure_a_pa", "Pa", r.pressure_a_pa)                            \
  X("pressure_b_pa", "Pa", r.pressure_b_pa)                            \
  X("pi_integral", "opening", r.integral)                              \
  X("state", "AxisState", static_cast<double>(r.state))                \
  X("mode", "ControlMode", static_cast<double>(r.mode))                \
  X("valve_enabled", "0/1", static_cast<double>(r.valve_enabled))      \
  X("fault_bits", "fault_bit() mask", static_cast<double>(r.active_faults)) \
  X("fault_reason", "FaultReason", static_cast<double>(r.fault_reason)) \
  X("lateness_ns", "ns", static_cast<double>(r.lateness_ns))           \
  X("exec_ns", "ns", static_cast<double>(r.exec_ns))

}  // namespace hsa::daemon
