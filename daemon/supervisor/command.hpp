// Operator commands to one axis and the supervisor's answer to each: the one vocabulary of a
// command from the LCM bridge's validation (which makes an AxisCommand out of a command_t) to the
// supervisor (which acts on it). The operator thread takes what must not reach the RT thread
// (gains, checked there; a reset, which recovers drivers first) and passes the rest on as is.
//
// A command is plain data with a sequence number: the RT side keeps the latest command in the
// operator-input struct and the supervisor acts once per new `seq`, so passing the same struct
// every cycle is harmless. A refused command carries a reason from a fixed list with a static
// text, so the RT thread never formats a string.
#pragma once

#include <cstdint>
#include <string_view>

#include "control/control_law.hpp"
#include "control/excitation_sequence.hpp"
#include "daemon/supervisor/capture_request.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

// X(kind, name): the commands an axis takes. gains never reaches the supervisor: the operator thread
// checks them and hands them to the law (AxisLoop::request_gains). Nor does capture: the RT cycle
// hands it to the axis's flight recorder (DaemonCycle, AxisRecorder::apply).
#define HSA_COMMAND_KINDS(X) \
  X(enable, "enable")        \
  X(disable, "disable")      \
  X(reset, "reset")          \
  X(set_mode, "mode")        \
  X(move_to, "move_to")      \
  X(gains, "gains")          \
  X(excite, "excite")        \
  X(capture, "capture")

enum class CommandKind : std::uint8_t {
  none,
#define HSA_COMMAND_ENUMERATOR(kind, name) kind,
  HSA_COMMAND_KINDS(HSA_COMMAND_ENUMERATOR)
#undef HSA_COMMAND_ENUMERATOR
};

// A move to a position at bounded speed and acceleration (move_to).
struct MoveRequest {
  double target_m = 0.0;
  // 0: the axis's (its move_speed_m_s, at most max_speed_m_s) and max_accel_m_s2 (SupervisorParams,
  // move_bounds), each at most what the plant follows in the move's direction (its capability)
  double speed_m_s = 0.0;
  double accel_m_s2 = 0.0;
};

// The longest opening the axis times itself (command_t.opening_duration_s): a slip of the keyboard
// must not hold a valve open for hours.
inline constexpr double kMaxOpeningDurationS = 600.0;

// A closed-loop identification run (excite; Puglisi et al. 2015, section 3.1.1): the rod setpoint
// is the working point plus a PRMS or PRBS (control/excitation_sequence.hpp), followed by a
// proportional controller (integral off) of gain kp_per_m, for duration_s. The operator thread
// resolves at_rod into working_point_m and checks the request against the axis's limits
// (daemon/hsad/excitation_gate.hpp) before the supervisor sees it.
struct ExcitationRequest {
  double working_point_m = 0.0;
  bool at_rod = false;               // the working point is where the rod is when it starts
  control::ExcitationKind kind = control::ExcitationKind::prms;
  double amplitude_m = 0.0;          // > 0
  double switching_time_s = 0.0;     // > 0: the shortest time between level changes
  int levels = 0;                    // PRMS: >= 2
  std::uint64_t seed = 1;
  double duration_s = 0.0;           // (0, kMaxExcitationDurationS]
  double kp_per_m = 0.0;             // the P gain, valve opening per metre of error, > 0
};

// The excitation's P gain when the command gives none: 0.2 per mm, the underdamped loop Puglisi et
// al. (2015, section 3.1.1) identify in (tests/analyze/identification_run.hpp models that run).
inline constexpr double kDefaultExcitationKpPerM = 200.0;
// The longest excitation: as for a timed opening, a slip of the keyboard must not run for hours.
inline constexpr double kMaxExcitationDurationS = 600.0;
// The most PRMS levels a command may ask for (command_t.excite_levels is an int16).
inline constexpr int kMaxExcitationLevels = 1000;

// Only the fields its kind names are meaningful; validation zeroes the others.
struct AxisCommand {
  std::uint64_t seq = 0;  // 0 = no command yet; a new value = a new command
  CommandKind kind = CommandKind::none;
  ControlMode mode = ControlMode::position;  // set_mode
  MoveRequest move{};                        // move_to
  std::uint64_t ticket = 0;  // the operator thread's name for this command (0: the daemon's own)
  // set_mode to open loop with an opening: the setpoint the mode starts with, in [-1, 1].
  bool has_opening = false;
  double opening = 0.0;
  // With an opening: how long the axis holds it before it commands opening 0 itself, s, in
  // [0, kMaxOpeningDurationS]; 0: until the next opening or the setpoint timeout.
  double opening_duration_s = 0.0;
  control::RuntimeGains gains{};  // gains
  ExcitationRequest excite{};      // excite
  CaptureRequest capture{};        // capture
};

enum class Refusal : std::uint8_t {
  none,             // accepted
  reset_first,      // enable while FAULT
  estop_active,     // enable while ESTOP
  estop_pressed,    // reset while the e-stop is still asserted
  cause_present,    // reset while a fault's cause is still there (see CommandOutcome::blocking)
  starting,         // enable or reset while INIT waits for the first sample of every input
  not_enabled,      // move_to while not ENABLED
  not_position_mode,  // move_to in open-loop mode
  target_outside_limits,  // move_to a target outside the soft limits
  speed_over_limit,   // move_to faster than the axis's max_speed_m_s
  excitation_outside_limits,  // excite whose working point ± amplitude leaves the soft limits
  excitation_invalid,  // excite with parameters the sequence refuses (caught before, on the operator thread)
  accel_over_limit,   // move_to with an acceleration over the axis's move max_accel_m_s2
  // move_to faster, or with a harder acceleration, than the plant can follow in the direction it
  // travels (the plant set's capability: SupervisorParams::capability).
  speed_over_extend_capability,
  speed_over_retract_capability,
  accel_over_extend_capability,
  accel_over_retract_capability,
  no_recorder,        // capture on an axis without a flight recorder
};

// The outcome of the last command handled, for status.
struct CommandOutcome {
  std::uint64_t seq = 0;
  std::uint64_t ticket = 0;  // the command's ticket (AxisCommand::ticket)
  CommandKind kind = CommandKind::none;
  bool accepted = false;
  Refusal refusal = Refusal::none;
  FaultReason blocking = FaultReason::none;  // with cause_present: the cause still there
};

std::string_view to_string(CommandKind kind) noexcept;
// A static sentence, e.g. Refusal::reset_first → "axis in FAULT: reset first".
std::string_view to_string(Refusal refusal) noexcept;

}  // namespace hsa::daemon
