// The plain structs that cross the SPSC rings between the LCM thread and the RT thread.
//
// They are the RT side's view of the LCM messages: trivially copyable (so a ring slot is a
// memcpy), fixed size (no std::string or vector, so the RT thread never allocates to produce or
// consume one) and already validated when they leave the LCM thread. Setpoints and commands go
// LCM → RT; telemetry and status samples go RT → LCM, where the bridge turns them into
// hsa::telemetry_t / hsa::status_t. The Msg* enums are the wire's vocabulary: their values equal
// the constants of msgs/*.lcm (static_asserts in message_validation.cpp and message_conversion.cpp),
// so the conversion is a cast. They are deliberately not the supervisor's own AxisState,
// ControlMode, CommandKind and FaultReason: whoever wires the RT side maps one onto the other, and
// the wire format does not change when the state machine does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace hsa::daemon {

// --- LCM → RT ------------------------------------------------------------------------------------

// A validated setpoint: position inside the axis's range, everything finite.
struct SetpointMsg {
  std::int64_t utime = 0;           // sender's timestamp, µs
  std::int64_t seq = 0;
  double position_m = 0.0;
  bool has_velocity_ff = false;
  double velocity_ff_m_s = 0.0;     // 0 when !has_velocity_ff
};

enum class MsgCommandKind : std::int8_t { enable = 1, disable = 2, reset = 3, mode = 4, gains = 5, move_to = 8 };
enum class MsgControlMode : std::int8_t { position = 1, valve_opening = 2 };

// Room for an operator id (1 to 32 characters) and its NUL.
inline constexpr std::size_t kOperatorIdSize = 33;

// A validated command. Only the fields its kind names are meaningful; the others are zero.
struct CommandMsg {
  std::int64_t utime = 0;
  std::int64_t seq = 0;
  char operator_id[kOperatorIdSize] = {};  // whose command (NUL-terminated), for the result in status
  std::int64_t counter = 0;                // its authentication counter, which the sender waits for
  MsgCommandKind kind = MsgCommandKind::disable;
  MsgControlMode mode = MsgControlMode::position;  // kind == mode
  double valve_opening = 0.0;               // kind == mode && mode == valve_opening, in [-1, 1]
  double kp = 0.0;                          // kind == gains, > 0
  double ki = 0.0;                          // kind == gains, >= 0
  double target_m = 0.0;                    // kind == move_to, finite
  double speed_m_s = 0.0;                   // kind == move_to, >= 0 (0: the axis's speed limit)
  double accel_m_s2 = 0.0;                  // kind == move_to, >= 0 (0: that speed in 0.1 s)
};

// --- RT → LCM ------------------------------------------------------------------------------------

enum class MsgAxisState : std::int8_t { init = 0, disabled = 1, enabled = 2, fault = 3, estop = 4 };

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
  MsgAxisState state = MsgAxisState::init;
  bool holding = false;
  std::int32_t lateness_ns = 0;
  std::int32_t lateness_max_ns = 0;
  std::int32_t exec_time_ns = 0;
  std::int32_t exec_time_max_ns = 0;
  std::int64_t overruns = 0;
};

enum class MsgFaultCode : std::int8_t {
  sensor = 1,
  encoder = 2,
  pressure = 3,
  soft_limit = 4,
  following_error = 5,
  current_saturation = 6,
  overruns = 7,
  driver = 8,
  estop = 9,
  blind_time = 10,
  control_output = 11,
  inputs_not_ready = 12,
};

// A latched fault with its reason. The text is a fixed array so that filling it in the RT thread
// needs no allocation; the bridge turns it into a string on the LCM thread.
struct FaultEntry {
  // Room for a driver error with its device's reason (a Modbus exception, its block and link).
  static constexpr std::size_t kReasonSize = 256;
  MsgFaultCode code = MsgFaultCode::sensor;
  char reason[kReasonSize] = {};    // NUL-terminated (the bridge stops at the array's end anyway)
};

// One driver of an axis, for status (msgs/driver_status_t.lcm), in fixed arrays.
struct DriverEntry {
  static constexpr std::size_t kNameSize = 40;
  static constexpr std::size_t kMaxCounters = 6;
  enum class Link : std::int8_t { none = 0, up = 1, down = 2 };  // driver_status_t.LINK_*
  char name[kNameSize] = {};
  char plugin[kNameSize] = {};
  char state[16] = {};
  char failure[FaultEntry::kReasonSize] = {};
  Link link = Link::none;
  char last_error[FaultEntry::kReasonSize] = {};
  std::uint8_t num_counters = 0;
  char counter_name[kMaxCounters][kNameSize] = {};
  std::int64_t counter_value[kMaxCounters] = {};
};

// The RT side's part of an axis's status; the bridge adds its own counters when it publishes.
struct StatusSample {
  static constexpr std::size_t kMaxFaults = 9;  // one per fault class

  std::int64_t utime = 0;
  MsgAxisState state = MsgAxisState::init;
  MsgControlMode mode = MsgControlMode::position;
  bool holding = false;
  std::uint8_t num_faults = 0;                  // entries of `faults` in use, <= kMaxFaults
  FaultEntry faults[kMaxFaults] = {};

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
  char gains_refusal[FaultEntry::kReasonSize] = {};  // NUL-terminated; empty: none refused

  // The drivers the axis's signals are bound to.
  static constexpr std::size_t kMaxDrivers = 8;
  std::uint8_t num_drivers = 0;
  DriverEntry drivers[kMaxDrivers] = {};

  // The answer to the last command the axis handled: whose, carried out or not, and why not.
  char result_operator[kOperatorIdSize] = {};
  std::int64_t result_counter = 0;
  bool result_accepted = false;
  char result_reason[FaultEntry::kReasonSize] = {};  // NUL-terminated; empty when accepted
};

static_assert(std::is_trivially_copyable_v<SetpointMsg>);
static_assert(std::is_trivially_copyable_v<CommandMsg>);
static_assert(std::is_trivially_copyable_v<TelemetrySample>);
static_assert(std::is_trivially_copyable_v<StatusSample>);

}  // namespace hsa::daemon
