// What one axis reports after each cycle: a plain, trivially copyable struct the RT thread hands
// to the operator thread (the port's latest-state buffer) and turns into telemetry samples. SI
// units. Only what a reader uses is here; the loop's inner states (the PI's limited setpoint, the
// supervisor's counters) are read from AxisLoop::law() and AxisLoop::supervisor().
#pragma once

#include <cstdint>
#include <type_traits>

#include "daemon/axis/input_age.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

struct AxisTelemetry {
  std::int64_t t_ns = 0;           // cycle time on the daemon's clock
  std::uint64_t cycle = 0;         // cycles run by this axis
  std::int64_t setpoint_utime = 0; // the sender's utime of the setpoint being followed

  double setpoint = 0.0;              // position mode: rod setpoint (m), after hold and soft limits
                                      // open loop: opening requested
  double position_m = 0.0;
  double velocity_m_s = 0.0;          // filtered difference of encoder samples
  double pressure_a_pa = 0.0;
  double pressure_b_pa = 0.0;
  double pressure_load_pa = 0.0;      // p_A − α·p_B
  double opening = 0.0;               // valve opening u the loops asked for, [-1, 1]
  double spool_position_m = 0.0;      // proportional drive: LVDT; else 0
  double command = 0.0;               // what the valve command output holds (A or opening)
  bool valve_enabled = false;
  double following_error_m = 0.0;     // limited setpoint − position
  // The age of each input's sample, indexed by FaultSignal − 1 (unbound inputs: age −1).
  InputAge inputs[kFaultSignalCount]{};
  bool estop = false;                 // the e-stop input asserted (false: none bound)

  AxisState state = AxisState::init;
  ControlMode mode = ControlMode::position;
  bool holding = false;               // setpoint silence
  bool exciting = false;              // an excitation drives the setpoint (excite)
  FaultRecord fault{};                // latched; reason none when healthy
  std::uint32_t active_faults = 0;    // fault_bit() flags present this cycle
  CommandOutcome last_command{};

  std::uint64_t param_changes_applied = 0;
  double kp = 0.0;  // the PI gains in use after this cycle
  double ki = 0.0;
};

// Copied into a ring by value on the RT thread.
static_assert(std::is_trivially_copyable_v<AxisTelemetry>);

}  // namespace hsa::daemon
