// What one axis reports after each cycle: a plain, trivially copyable struct the RT thread pushes
// into a ring as is. SI units; the LCM side converts and decimates.
#pragma once

#include <cstdint>
#include <type_traits>

#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

struct AxisTelemetry {
  std::int64_t t_ns = 0;           // cycle time on the daemon's clock
  std::uint64_t cycle = 0;         // cycles run by this axis
  std::int64_t setpoint_utime = 0; // the sender's utime of the setpoint being followed
  std::uint64_t setpoint_seq = 0;

  double setpoint = 0.0;              // position mode: rod setpoint (m), after hold and soft limits
                                      // open loop: opening requested
  double limited_setpoint_m = 0.0;    // the PI's rate-limited setpoint
  double position_m = 0.0;
  double velocity_m_s = 0.0;          // filtered difference of encoder samples
  double pressure_a_pa = 0.0;
  double pressure_b_pa = 0.0;
  double pressure_load_pa = 0.0;      // p_A − α·p_B
  double opening = 0.0;               // valve opening u the loops asked for, [-1, 1]
  double spool_position_m = 0.0;      // proportional drive: LVDT; else 0
  double spool_reference_m = 0.0;
  double command = 0.0;               // what the valve command output holds (A or opening)
  bool command_saturated = false;     // the law's command at its limit, or clamped by the output, this cycle
  bool valve_enabled = false;
  double following_error_m = 0.0;     // limited setpoint − position

  AxisState state = AxisState::init;
  ControlMode mode = ControlMode::position;
  bool holding = false;               // setpoint silence
  FaultRecord fault{};                // latched; reason none when healthy
  std::uint32_t active_faults = 0;    // fault_bit() flags present this cycle
  CommandOutcome last_command{};

  std::uint64_t faults_tripped = 0;
  std::uint64_t commands_refused = 0;
  std::uint64_t setpoints_received = 0;
  std::uint64_t param_changes_applied = 0;
  double kp = 0.0;  // the PI gains in use after this cycle
  double ki = 0.0;
};

// Copied into a ring by value on the RT thread.
static_assert(std::is_trivially_copyable_v<AxisTelemetry>);

}  // namespace hsa::daemon
