// What crosses an axis's port (axis_port.hpp) besides the supervisor's own SetpointInput and
// AxisCommand: a command with whom to answer, a telemetry sample, a status sample.
//
// All are trivially copyable (a ring slot is a memcpy) and fixed size (no std::string or vector,
// so neither side allocates to produce or consume one). The RT thread produces telemetry samples;
// the operator thread produces status samples, where fault and refusal texts are formatted; the
// LCM bridge turns both into hsa::telemetry_t / hsa::status_t (message_conversion.hpp), which is
// the one place the wire's constants meet the supervisor's enums.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "daemon/axis/input_age.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

// Room for an operator id (1 to 32 characters) and its NUL.
inline constexpr std::size_t kOperatorIdSize = 33;
// Room for a sentence: a fault with its device's reason (a Modbus exception, its block and link).
inline constexpr std::size_t kReasonSize = 256;

// Whose command it is: what its answer in status names (status_t.result_operator, result_counter).
struct CommandSender {
  char operator_id[kOperatorIdSize] = {};  // NUL-terminated
  std::int64_t counter = 0;                // its authentication counter, which the sender waits for
};

// A validated command from the LCM thread to the operator thread.
struct OperatorCommand {
  AxisCommand command;
  CommandSender from;
};

// --- RT → LCM ------------------------------------------------------------------------------------

// One RT cycle's view of an axis. The RT thread chooses which cycles to push on `tick` (the RT
// base-tick index), which is exact whatever the wake-up jitter of the cycle.
struct TelemetrySample {
  std::int64_t utime = 0;           // CLOCK_MONOTONIC time of the cycle, µs
  std::uint64_t tick = 0;           // RT base-tick index
  double position_m = 0.0;
  double velocity_m_s = 0.0;
  double pressure_a_pa = 0.0;
  double pressure_b_pa = 0.0;
  double load_pressure_pa = 0.0;
  double spool_position_m = 0.0;
  double setpoint_m = 0.0;
  double following_error_m = 0.0;
  double valve_opening = 0.0;
  double current_ref_a = 0.0;
  bool valve_enabled = false;
  std::int64_t setpoint_utime = 0;  // sender's utime of the setpoint in effect (0: none yet)
  AxisState state = AxisState::init;
  bool holding = false;
  bool exciting = false;
  std::int32_t lateness_ns = 0;
  std::int32_t lateness_max_ns = 0;
  std::int32_t exec_time_ns = 0;
  std::int32_t exec_time_max_ns = 0;
  std::int64_t overruns = 0;
  InputAge inputs[kFaultSignalCount]{};  // AxisTelemetry::inputs
  bool estop = false;
};

// --- operator → LCM ------------------------------------------------------------------------------

// One driver of an axis, for status (msgs/driver_status_t.lcm), in fixed arrays.
struct DriverEntry {
  static constexpr std::size_t kNameSize = 40;
  static constexpr std::size_t kMaxCounters = 6;
  enum class Link : std::int8_t { none = 0, up = 1, down = 2, not_answering = 3 };  // driver_status_t.LINK_*
  char name[kNameSize] = {};
  char plugin[kNameSize] = {};
  char state[16] = {};
  char failure[kReasonSize] = {};
  Link link = Link::none;
  char last_error[kReasonSize] = {};
  std::uint8_t num_counters = 0;
  char counter_name[kMaxCounters][kNameSize] = {};
  std::int64_t counter_value[kMaxCounters] = {};
};

// The axis's answer to one command: whose, carried out or not, and why not.
struct CommandResultEntry {
  CommandSender from;
  bool accepted = false;
  char reason[kReasonSize] = {};  // NUL-terminated; empty when accepted
};

// The operator thread's part of an axis's status; the bridge adds its own counters when it
// publishes.
struct StatusSample {
  std::int64_t utime = 0;
  AxisState state = AxisState::init;
  ControlMode mode = ControlMode::position;
  bool holding = false;
  bool exciting = false;  // an excitation (excite) drives the setpoint
  // The latched fault (none when healthy) and its sentence, formatted on the operator thread.
  FaultReason fault = FaultReason::none;
  char fault_text[kReasonSize] = {};  // NUL-terminated (the bridge stops at the array's end anyway)

  std::int64_t rt_overruns = 0;
  std::int64_t rt_allocations = 0;
  std::int64_t rt_locks = 0;
  std::int64_t rt_minor_faults = 0;
  std::int64_t rt_major_faults = 0;

  bool sched_fifo = false;
  bool memory_locked = false;
  std::int16_t rt_priority = 0;
  std::int16_t rt_cpu = -1;

  // GAINS commands: the PI gains in use, changes applied, and those refused by the axis (outside
  // its max_kp/max_ki) with the last refusal's reason.
  double kp = 0.0;
  double ki = 0.0;
  std::int64_t gain_changes_applied = 0;
  std::int64_t gain_changes_refused = 0;
  char gains_refusal[kReasonSize] = {};  // NUL-terminated; empty: none refused

  // The flight recorder (docs/flight-recorder.md): files written, triggers merged into a capture
  // still collecting, captures given up (dropped), captures that could not be written, and the
  // condition armed ("" none; "following_error_m above 0.001 (single)").
  std::int64_t captures_written = 0;
  std::int64_t capture_triggers_merged = 0;
  std::int64_t capture_triggers_dropped = 0;
  std::int64_t capture_write_failures = 0;
  char capture_condition[kReasonSize] = {};  // NUL-terminated

  // The drivers the axis's signals are bound to.
  static constexpr std::size_t kMaxDrivers = 8;
  std::uint8_t num_drivers = 0;
  DriverEntry drivers[kMaxDrivers] = {};

  // The answers to the most recent commands, oldest first: every command gets its own, however
  // many arrive between two status messages (status_t.result_*).
  static constexpr std::size_t kMaxResults = 16;
  std::uint8_t num_results = 0;
  CommandResultEntry results[kMaxResults] = {};
};

static_assert(std::is_trivially_copyable_v<OperatorCommand>);
static_assert(std::is_trivially_copyable_v<TelemetrySample>);
static_assert(std::is_trivially_copyable_v<StatusSample>);

}  // namespace hsa::daemon
