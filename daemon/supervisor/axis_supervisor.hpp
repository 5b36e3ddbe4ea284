// The safety state machine of one axis: pure logic, no I/O, no clock, no allocation.
//
// Every cycle the axis loop calls update() once with the samples it read, the time, the
// executive's health inputs and the operator's latest setpoint and command. update() judges the
// inputs, moves the state machine and answers with a Decision the loop applies in the same cycle:
// so a fault detected now puts the valve in its safe state now.
//
// Rules:
// - Fault conditions are evaluated every cycle. A condition trips a fault from INIT, DISABLED and
//   ENABLED; the first (by FaultReason priority) is latched in fault() until a reset succeeds.
//   The e-stop goes to ESTOP from any state but FAULT: a latched fault keeps its first cause,
//   and an e-stop asserted meanwhile is a present cause that refuses the reset.
// - Commands are handled after the faults, so an enable arriving in the cycle a fault trips is
//   refused ("reset first").
// - Time: blind_time trips while ENABLED when the time since the previous cycle (cycle_gap_ns)
//   exceeds max_blind_time_ns, however few cycles overran: for that long the valve held a command
//   computed for a rod that has since moved. The condition exists only in the cycle that follows
//   the gap, so it never blocks a reset: the reset is handled in a later cycle, and if that one is
//   late too the axis is not ENABLED there, where a late cycle changes nothing the valve sees.
// - Samples are judged by their timestamps: every bound input of the input table
//   (axis_inputs.hpp) whose timestamp has not changed for longer than input_stale_ns trips the
//   table's class for it with status stale, naming the signal (sensor_not_ok; the e-stop: estop,
//   as an unreadable loop counts as pressed; the encoder also faults after encoder_stale_cycles cycles without a fresh sample). An encoder jump is judged against the time between the two samples:
//   allowed = max_speed_m_s · Δt + encoder_jump_max_m, so a slow or late bus (10 ms between
//   samples) does not fault a rod moving within its speed bound, and a real jump still does.
//   With no speed bound (infinite) only encoder_jump_max_m is allowed per sample.
// - A non-finite loop output is caught by the loop after update() (output_not_finite()), which
//   latches control_output and puts the valve in its safe state in that same cycle.
// - reset succeeds only when no latched-class condition is present now. Transient classes (a jump,
//   a soft-limit crossing, a following error, a saturation streak) are gone once the loops are
//   frozen; the others (sensor status, staleness, pressure, overrun streak, driver error, e-stop)
//   must clear first, and the refusal names the one still there.
// - Soft limits are judged while ENABLED only, and they clamp the position setpoint, to
//   kSoftLimitSetpointMarginM inside them so that the loop's overshoot does not fault. A rod that
//   stopped outside them (after a soft-limit fault, the valve closes a little past the limit) can
//   be reset and enabled again, and then only recovers, as LinuxCNC lets a joint past its soft
//   limit jog inward only: the held position is clamped into the limits, so position mode drives
//   the rod back in (the following-error check guards that move), open-loop openings are held at
//   0, and the soft-limit check is re-armed once the rod is inside the limits and a new setpoint
//   has been received since the enable. Enabled inside the limits, it is armed at once.
// - Setpoint silence: ENABLED with no new setpoint since enable, or none for longer than
//   setpoint_timeout_ns, holds the position measured when the silence began (open loop: opening
//   0) and reports holding. It is not a fault; the next new setpoint is followed again.
// - A set_mode to open loop that carries an opening (AxisCommand::has_opening) takes that opening
//   as a new setpoint in the same cycle, so one MODE message opens the valve. With a duration
//   (AxisCommand::opening_duration_s) the axis holds that opening, without setpoint silence, until
//   the first cycle at or past its end, and commands opening 0 from there on: the opening lasts
//   what was asked to the base tick, however late a sender's next message would have come. A new
//   setpoint or opening, a mode change or leaving ENABLED ends it.
// - On enable, on a mode change and on a gain change the loop re-activates the cascade from the
//   measured state (Decision::activate), so nothing jumps.
// - A move (move_to) is a setpoint the supervisor generates itself: from where the setpoint is
//   now to a target inside the soft limits, on a jerk-limited profile (control/jerk_limited_profile)
//   at the requested speed (at most max_speed_m_s; 0 means move_speed_m_s) and acceleration (at
//   most max_accel_m_s2, refused above; 0 means max_accel_m_s2) with the axis's jerk. With a plant
//   set (SupervisorParams::capability) the direction the move travels bounds it too: a speed or an
//   acceleration over that direction's limit is refused naming the direction, and a move that asks
//   for none gets the smaller of the axis's and the direction's (slowed, not refused); the Decision
//   carries its velocity, acceleration and jerk for the law's feed-forward, and move_under_way
//   until the profile ends (the PI holds its integrator meanwhile). Then it holds the target, without setpoint silence. It needs
//   ENABLED in position mode; a streamed setpoint, a mode change, a disable or a fault ends it.
// - A streamed setpoint (take_setpoint) in position mode is the operator's wish, which may ask for
//   more than the axis has (a step, a fast sine): it reaches the loop through a time-optimal
//   limiter (control/setpoint_limiter.hpp) bounded by max_speed_m_s and the moves' acceleration
//   bound (move_bounds), inside the soft limits; the limiter's velocity and its acceleration
//   (low-passed, kStreamAccelFilterS) are the feed-forward. It starts from the last rod setpoint (the held position, a move's or an
//   excitation's setpoint) with that setpoint's velocity, so the first streamed sample bumps
//   nothing, and starts afresh after any cycle that did not follow the stream (holding, a move, an
//   excitation, open loop, not ENABLED). The target's velocity is the one the stream gives, or,
//   when it gives none, the stream's pace (the last two targets' difference over the time between
//   them): a stream of positions alone (hsactl sine) is followed without lag. The cycles in which
//   its output lagged the stream by more than kSlowedSetpointM count in setpoint_cycles_limited().
//   With no finite speed or acceleration bound the stream goes to the loop as it is.
// - An excitation (excite; Puglisi et al. 2015, section 3.1.1) is a setpoint the supervisor
//   generates too: the working point plus a PRMS or PRBS level (excitation_run.hpp), with no
//   velocity feed-forward, which Decision::exciting tells the loop to follow with the request's P
//   gain and the integral off. It needs ENABLED in position mode and working point ± amplitude
//   inside the soft limits (the operator thread checked the rest: daemon/hsad/excitation_gate.hpp).
//   Every fault stays armed. A disable, a fault, a streamed setpoint, a MODE command, a gain change
//   (stop_excitation) and an accepted move or excite end it (a refused one changes nothing); at
//   its duration's end the axis holds the working point (holding, as after setpoint silence)
//   until the next setpoint.
// - Start-up: INIT judges no input before every bound input has delivered a first sample (its
//   status is no longer disconnected), because a bus driver has nothing to hand over before its
//   first poll, and a device that answers a little late is not an e-stop. Only what needs no
//   input is judged meanwhile (driver error, overruns) and an e-stop that reads asserted. After
//   startup_timeout_ns without every first sample, inputs_not_ready trips, naming the first
//   input still missing; enable and reset are refused (starting) while INIT waits.
#pragma once

#include <cstdint>
#include <limits>

#include "control/jerk_limited_profile.hpp"
#include "control/setpoint_limiter.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/excitation_run.hpp"
#include "daemon/supervisor/fault.hpp"
#include "daemon/supervisor/motion_capability.hpp"
#include "daemon/supervisor/operator_input.hpp"
#include "daemon/supervisor/safety_defaults.hpp"
#include "drivers/signal.hpp"

namespace hsa::daemon {

// Thresholds in the units the supervisor counts (base ticks, ns). Their defaults are
// safety_defaults.hpp's at the default base period; hsad derives them from the configuration.
struct SupervisorParams {
  double soft_limit_low_m = 0.005;
  double soft_limit_high_m = 0.299;
  double pressure_max_pa = 26e5;
  double following_error_max_m = 0.010;
  std::uint32_t following_error_cycles =  // over the limit this many cycles in a row
      safety_defaults::ticks_in(safety_defaults::kFollowingErrorS, safety_defaults::kBasePeriodS);
  // The margin a position may move between two samples on top of max_speed_m_s × their Δt
  // (quantisation, noise); with an infinite speed bound, the whole per-sample allowance.
  double encoder_jump_max_m = 0.005;
  // The axis's speed bound (the PI's setpoint rate limit, max_speed_m_s in the configuration).
  double max_speed_m_s = std::numeric_limits<double>::infinity();
  // A move's bounds (move_to): its speed when it asks for none (at most max_speed_m_s), the largest
  // acceleration it may ask for and the one it gets when it asks for none, and the jerk of every
  // move. Infinite: derived from the speed (safety_defaults::kDefaultRampS, kDefaultJerkRampS).
  double move_speed_m_s = std::numeric_limits<double>::infinity();
  double max_accel_m_s2 = std::numeric_limits<double>::infinity();
  double max_jerk_m_s3 = std::numeric_limits<double>::infinity();
  // What the plant can follow per direction (motion_capability.hpp): a move's bounds in the
  // direction it travels on top of the ones above. Infinite: no plant set.
  MotionCapability capability{};
  std::uint32_t encoder_stale_cycles =  // cycles without a new encoder timestamp
      safety_defaults::ticks_in(safety_defaults::kEncoderStaleS, safety_defaults::kBasePeriodS);
  std::int64_t input_stale_ns = static_cast<std::int64_t>(safety_defaults::kInputStaleS * 1e9);
  std::int64_t max_blind_time_ns = static_cast<std::int64_t>(safety_defaults::kMaxBlindTimeS * 1e9);
  std::uint32_t saturation_cycles =  // saturated command this many cycles in a row
      safety_defaults::ticks_in(safety_defaults::kCurrentSaturationS, safety_defaults::kBasePeriodS);
  std::uint32_t overrun_streak_max = safety_defaults::kOverrunStreak;
  std::int64_t setpoint_timeout_ns = static_cast<std::int64_t>(safety_defaults::kSetpointTimeoutS * 1e9);
  std::int64_t startup_timeout_ns = static_cast<std::int64_t>(safety_defaults::kStartupTimeoutS * 1e9);
};

// One cycle's view of the axis.
struct SupervisorInputs {
  std::int64_t t_ns = 0;
  std::int64_t cycle_gap_ns = 0;  // t_ns minus the previous cycle's t_ns (0: no previous cycle)
  // Per input of the table (axis_inputs.hpp): its sample (a digital one true = asserted), and
  // has_<input>, whether it is bound: only a bound input is judged, and a required one is.
#define HSA_SUPERVISOR_INPUT(signal, name, kind, presence, unreadable) \
  InputSample<InputKind::kind> signal;                                  \
  bool has_##signal = InputPresence::presence == InputPresence::required;
  HSA_AXIS_INPUTS(HSA_SUPERVISOR_INPUT)
#undef HSA_SUPERVISOR_INPUT
  // From the loops of the previous cycle (the loop's own outputs lag one cycle by nature).
  double following_error_m = 0.0;  // limited setpoint − position; judged in ENABLED position mode
  bool command_saturated = false;  // the law's command at its limit (ControlLaw::saturated) or clamped by the output
  ExecutiveInputs executive;
};

// The acceleration bound and the jerk of a move under `params` (their infinite defaults resolved),
// whichever way it travels; the direction's capability bounds it further (start_move).
struct MoveBounds {
  double accel_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;
};
MoveBounds move_bounds(const SupervisorParams& params) noexcept;

// How far a streamed setpoint's limited value may lag the stream before the cycle counts as
// limited (setpoint_cycles_limited): a stream sampled at 1 kHz is itself a staircase whose steps
// are 0.15 mm at the example's speed bound, which the limiter smooths without slowing anything.
inline constexpr double kSlowedSetpointM = 0.5e-3;

// How far inside the soft limits the rod setpoint stays (every mode: a stream, a move, a hold,
// an excitation). The soft-limit fault judges the measured rod, and a rod held on a setpoint
// exactly at a limit crosses it by the first micrometre of overshoot or hunting: a MOVE_TO to
// the limit, which hsad accepts, would fault. The loop's overshoot at the end of a move at the
// example's bounds is at most 0.2 mm (tests/daemon/test_moves.cpp), its hunting at rest the
// integral dead band (5 µm); 0.5 mm leaves room for both.
inline constexpr double kSoftLimitSetpointMarginM = 0.5e-3;

// The time constant of the low-pass filter on the limiter's acceleration before it is the
// feed-forward's. A stream sampled at 1 kHz is a staircase at the 10 kHz cycle, and a
// time-optimal limiter answers each stair at its full acceleration, ±max_accel_m_s2: fed to the
// valve that is ±0.08 of opening at the example's bounds, at the stream's rate. Averaged over ten
// stream samples it is the motion's acceleration again (on 5-20 mm sines at 0.5-1 Hz, within
// 0.05 m/s² of the sine's, 0.0025 of opening); the position and velocity are the limiter's own.
inline constexpr double kStreamAccelFilterS = 0.01;

struct Decision {
  AxisState state = AxisState::init;
  ControlMode mode = ControlMode::position;
  bool drive = false;     // ENABLED: tick the loops, write their command, valve enable on
  bool activate = false;  // re-activate the loops from the measured state before ticking
  bool holding = false;   // setpoint silence: holding position (or opening 0)
  double rod_setpoint_m = 0.0;  // position mode, kSoftLimitSetpointMarginM inside the soft limits
  double velocity_ff_m_s = 0.0; // position mode: the setpoint's velocity (a stream's, a move's; 0 holding)
  double accel_ff_m_s2 = 0.0;   // position mode: a move's acceleration (0 otherwise)
  double jerk_ff_m_s3 = 0.0;    // position mode: a move's jerk (0 otherwise)
  bool move_under_way = false;  // a move's profile has not ended yet (it then holds its target)
  // hsad plans the rod setpoint's path, not the operator: a move under way, or a stream the
  // limiter lags by more than kSlowedSetpointM. The PI holds its integrator (PiController,
  // conditional integration during a planned move).
  bool setpoint_planned = false;
  double opening = 0.0;         // open-loop mode, clamped to [-1, 1]
  // An excitation drives the setpoint: the loop follows it by P control, gain excite_kp_per_m.
  bool exciting = false;
  double excite_kp_per_m = 0.0;
  std::uint64_t excitation = 0;  // which run (counts from 1): a new one replaced the last
  bool tripped = false;         // a fault (or e-stop) tripped in this update
};

class AxisSupervisor {
 public:
  explicit AxisSupervisor(const SupervisorParams& params,
                          ControlMode initial_mode = ControlMode::position);

  Decision update(const SupervisorInputs& in, const AxisInputsFromOperator& op) noexcept;

  // Called by the loop in the cycle whose update() said drive, when the command it computed is
  // not finite: latches control_output (value = the command) and leaves ENABLED. The caller then
  // writes the safe command and switches the valve enable off in the same cycle.
  void output_not_finite(double command, std::int64_t t_ns) noexcept;
  // Ends a running excitation, the axis holding its working point (the loop calls it when new
  // gains arrive meanwhile: they apply from then on).
  void stop_excitation() noexcept;

  [[nodiscard]] AxisState state() const { return state_; }
  [[nodiscard]] ControlMode mode() const { return mode_; }
  // The latched fault (reason none when not in FAULT / ESTOP).
  [[nodiscard]] const FaultRecord& fault() const { return fault_; }
  // Conditions present in the last update, as fault_bit() flags: for status.
  [[nodiscard]] std::uint32_t active_faults() const { return active_; }
  [[nodiscard]] const CommandOutcome& last_command() const { return last_command_; }
  [[nodiscard]] std::uint64_t faults_tripped() const { return faults_tripped_; }
  [[nodiscard]] std::uint64_t commands_refused() const { return commands_refused_; }
  [[nodiscard]] std::uint64_t setpoints_received() const { return setpoints_received_; }
  // ENABLED position-mode cycles in which the limiter held the streamed setpoint more than
  // kSlowedSetpointM behind the stream: the operator asked for more than the axis has.
  [[nodiscard]] std::uint64_t setpoint_cycles_limited() const { return setpoint_cycles_limited_; }
  // The limiter of streamed setpoints (see the rules above); limiting_streams() false: none.
  [[nodiscard]] const control::SetpointLimiter& stream_limiter() const { return stream_limiter_; }
  [[nodiscard]] bool limiting_streams() const { return limit_streams_; }
  [[nodiscard]] const SupervisorParams& params() const { return params_; }
  // The profile of the last move started (what a move's setpoint follows while moving()).
  [[nodiscard]] const control::JerkLimitedProfile& move() const { return move_; }
  // False while an axis enabled outside its soft limits recovers (see the rules above).
  [[nodiscard]] bool soft_limits_armed() const { return soft_limits_armed_; }
  [[nodiscard]] bool exciting() const { return excitation_.active(); }

 private:
  // Fills conditions_[] and active_ for this cycle.
  void evaluate(const SupervisorInputs& in) noexcept;
  void set_condition(FaultReason reason, FaultSignal signal, io::SampleStatus status, double value,
                     double limit) noexcept;
  void trip(FaultReason reason, std::int64_t t_ns) noexcept;
  // Handles a new command; returns true when the loops must re-activate.
  bool handle(const AxisCommand& cmd, std::int64_t t_ns) noexcept;
  // A new operator setpoint (a streamed one, or the opening a set_mode carries).
  void take_setpoint(double target, double velocity_m_s, std::int64_t t_ns) noexcept;
  // Starts a move (handle's move_to), or refuses it with the reason.
  void start_move(const MoveRequest& move, std::int64_t t_ns) noexcept;
  // Starts an excitation (handle's excite), or refuses it with the reason.
  void start_excitation(const ExcitationRequest& request, std::int64_t t_ns) noexcept;
  void refuse(Refusal why, FaultReason blocking = FaultReason::none) noexcept;
  // Conditions that block a reset (see the header comment).
  [[nodiscard]] FaultReason persistent_cause() const noexcept;

  SupervisorParams params_;
  AxisState state_ = AxisState::init;
  ControlMode mode_;
  FaultRecord fault_{};
  FaultRecord conditions_[kFaultReasonCount]{};  // this cycle's, indexed by reason
  std::uint32_t active_ = 0;

  // Encoder history.
  bool have_position_ = false;
  double last_position_m_ = 0.0;
  std::int64_t last_position_stamp_ns_ = std::numeric_limits<std::int64_t>::min();
  std::uint32_t stale_cycles_ = 0;
  // Per input (indexed by FaultSignal − 1): the last timestamp seen and the cycle time it was
  // first seen at.
  struct Freshness {
    std::int64_t stamp_ns = 0;
    std::int64_t since_ns = 0;
    bool seen = false;
  };
  Freshness freshness_[kFaultSignalCount]{};
  void judge_age(Freshness& f, std::int64_t stamp_ns, std::int64_t t_ns, FaultSignal which,
                 FaultReason unreadable) noexcept;
  std::int64_t first_update_ns_ = 0;
  bool updated_ = false;
  std::uint32_t following_cycles_ = 0;
  std::uint32_t saturated_cycles_ = 0;
  bool inside_soft_limits_ = true;  // this cycle's usable position is within the soft limits
  bool soft_limits_armed_ = true;

  // Operator stream.
  std::uint64_t last_command_seq_ = 0;
  std::uint64_t last_setpoint_seq_ = 0;
  std::int64_t last_setpoint_ns_ = 0;
  double target_ = 0.0;               // the operator's latest setpoint: a position, or an opening
  double target_velocity_m_s_ = 0.0;  // its velocity feed-forward
  bool setpoint_since_enable_ = false;
  bool holding_ = false;
  double hold_position_m_ = 0.0;
  double last_rod_setpoint_m_ = 0.0;  // the rod setpoint of the last position-mode cycle that drove
  bool moving_ = false;               // a move_to is in progress or holds its target
  bool opening_timed_ = false;        // the open loop's opening ends at opening_ends_ns_
  std::int64_t opening_ends_ns_ = 0;
  control::JerkLimitedProfile move_;
  // Streamed setpoints in position mode (the rules above).
  control::SetpointLimiter stream_limiter_;
  bool limit_streams_ = false;        // the axis has finite speed and acceleration bounds
  bool stream_limiter_live_ = false;  // it followed the stream last cycle: step on, don't restart
  double last_velocity_ff_m_s_ = 0.0; // the velocity of the last rod setpoint (to start from)
  double stream_pace_m_s_ = 0.0;      // the last two streamed targets' difference over their interval
  double stream_accel_m_s2_ = 0.0;    // the limiter's acceleration, filtered (kStreamAccelFilterS)
  std::uint64_t setpoint_cycles_limited_ = 0;
  ExcitationRun excitation_;
  std::uint64_t excitations_started_ = 0;
  std::int64_t move_start_ns_ = 0;
  CommandOutcome last_command_{};

  std::uint64_t faults_tripped_ = 0;
  std::uint64_t commands_refused_ = 0;
  std::uint64_t setpoints_received_ = 0;
};

}  // namespace hsa::daemon
