#include "daemon/supervisor/axis_supervisor.hpp"

#include <algorithm>
#include <cmath>

namespace hsa::daemon {
namespace {

constexpr std::uint32_t bit(FaultReason r) { return fault_bit(r); }

// From the fault table (fault.hpp): what a class asks of the state machine.
constexpr std::uint32_t kEnabledOnly = fault_mask(fault_kind::enabled_only);
constexpr std::uint32_t kPersistent = fault_mask(fault_kind::persistent);
// What INIT judges before every input has delivered: the executive's reports, which need no input.
constexpr std::uint32_t kJudgedWhileStarting = fault_mask(fault_kind::while_starting);

// The highest-priority reason in a mask (lowest enumerator), or none.
FaultReason first_of(std::uint32_t mask) {
  for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
    if (mask & (1u << r)) return static_cast<FaultReason>(r);
  }
  return FaultReason::none;
}

// The band the rod setpoint is clamped to: the soft limits less kSoftLimitSetpointMarginM (their
// middle, for limits closer than twice the margin).
struct SetpointBand {
  double low_m, high_m;
};
SetpointBand setpoint_band(const SupervisorParams& p) {
  const double low = p.soft_limit_low_m + kSoftLimitSetpointMarginM;
  const double high = p.soft_limit_high_m - kSoftLimitSetpointMarginM;
  if (low <= high) return {low, high};
  const double middle = 0.5 * (p.soft_limit_low_m + p.soft_limit_high_m);
  return {middle, middle};
}

bool usable(const io::AnalogSample& s) { return s.ok() && std::isfinite(s.value); }
bool usable(const io::DigitalSample& s) { return s.ok(); }
// The value a record of an unusable sample keeps: a digital one's says nothing.
double recorded(const io::AnalogSample& s) { return s.value; }
double recorded(const io::DigitalSample&) { return 0.0; }

// Calls judge(sample, bound, signal, unreadable) for each input of the table, in its order.
template <class Judge>
void for_each_input(const SupervisorInputs& in, Judge&& judge) {
#define HSA_JUDGE_INPUT(signal, name, kind, presence, unreadable) \
  judge(in.signal, in.has_##signal, FaultSignal::signal, FaultReason::unreadable);
  HSA_AXIS_INPUTS(HSA_JUDGE_INPUT)
#undef HSA_JUDGE_INPUT
}

struct Missing {
  FaultSignal signal = FaultSignal::none;
  io::SampleStatus status = io::SampleStatus::ok;
};

// The first bound input (FaultSignal order) that has not delivered a sample yet.
Missing first_missing(const SupervisorInputs& in) {
  constexpr auto none_yet = io::SampleStatus::disconnected;
  Missing missing;
  for_each_input(in, [&](const auto& sample, bool bound, FaultSignal which, FaultReason) {
    if (missing.signal == FaultSignal::none && bound && sample.status == none_yet) missing = {which, none_yet};
  });
  return missing;
}

}  // namespace

AxisSupervisor::AxisSupervisor(const SupervisorParams& params, ControlMode initial_mode)
    : params_(params), mode_(initial_mode) {
  // The bounds moves use: a stream gets no more than a move may ask for.
  const SetpointBand band = setpoint_band(params);
  const control::SetpointLimits limits{params.max_speed_m_s, move_bounds(params).accel_m_s2, band.low_m,
                                       band.high_m};
  limit_streams_ = std::isfinite(limits.speed_m_s) && limits.speed_m_s > 0.0 && std::isfinite(limits.accel_m_s2) &&
                   limits.accel_m_s2 > 0.0 && std::isfinite(limits.low_m) && std::isfinite(limits.high_m) &&
                   limits.low_m < limits.high_m;
  if (limit_streams_) stream_limiter_ = control::SetpointLimiter(limits);
}

void AxisSupervisor::set_condition(FaultReason reason, FaultSignal signal, io::SampleStatus status,
                                   double value, double limit) noexcept {
  if (active_ & bit(reason)) return;  // keep the first signal found for a class
  active_ |= bit(reason);
  conditions_[static_cast<std::size_t>(reason)] = {reason, signal, status, value, limit, 0};
}

void AxisSupervisor::judge_age(Freshness& f, std::int64_t stamp_ns, std::int64_t t_ns, FaultSignal which,
                               FaultReason unreadable) noexcept {
  if (!f.seen || stamp_ns != f.stamp_ns) {
    f = {stamp_ns, t_ns, true};
    return;
  }
  const std::int64_t age = t_ns - f.since_ns;
  if (age > params_.input_stale_ns) {
    // An input that stopped reporting is as unusable as an unreadable one (an e-stop: pressed).
    set_condition(unreadable, which, io::SampleStatus::stale,
                  static_cast<double>(age) * 1e-9,
                  static_cast<double>(params_.input_stale_ns) * 1e-9);
  }
}

void AxisSupervisor::evaluate(const SupervisorInputs& in) noexcept {
  active_ = 0;
  using io::SampleStatus;
  const auto ok = SampleStatus::ok;

  if (in.cycle_gap_ns > params_.max_blind_time_ns) {
    set_condition(FaultReason::blind_time, FaultSignal::none, ok,
                  static_cast<double>(in.cycle_gap_ns) * 1e-9,
                  static_cast<double>(params_.max_blind_time_ns) * 1e-9);
  }

  // An unreadable e-stop loop counts as pressed too: the input table's class for it is estop.
  if (in.has_estop && in.estop.ok() && in.estop.value) {
    set_condition(FaultReason::estop, FaultSignal::estop, ok, 1.0, 0.0);
  }
  if (in.executive.driver_error) {
    set_condition(FaultReason::driver_error, FaultSignal::none, ok, 1.0, 0.0);
  }
  if (in.executive.overrun_streak >= params_.overrun_streak_max) {
    set_condition(FaultReason::rt_overruns, FaultSignal::none, ok, in.executive.overrun_streak,
                  params_.overrun_streak_max);
  }

  // Every bound input's status first, then every age: a bad sample is named before a stale one.
  for_each_input(in, [&](const auto& s, bool bound, FaultSignal which, FaultReason unreadable) {
    if (!bound || usable(s)) return;
    // A non-finite value with an ok status is as useless as an out-of-range one.
    set_condition(unreadable, which, s.ok() ? SampleStatus::out_of_range : s.status, recorded(s), 0.0);
  });
  const bool position_ok = usable(in.position);
  const bool pa_ok = usable(in.pressure_a);
  const bool pb_ok = usable(in.pressure_b);

  // Age by timestamp, for every bound input whose status is otherwise fine. Not while a driver of
  // the axis is in error: it is not being read, so its samples' age tells nothing that fault
  // does not (and a silent e-stop would turn a recoverable driver error into an ESTOP that the
  // driver's own recovery could never clear). The clocks restart once it reads again.
  const bool judge_ages = !in.executive.driver_error;
  for_each_input(in, [&](const auto& sample, bool bound, FaultSignal which, FaultReason unreadable) {
    Freshness& f = freshness_[static_cast<std::size_t>(which) - 1];
    if (judge_ages && bound && sample.ok()) {
      judge_age(f, sample.timestamp.count(), in.t_ns, which, unreadable);
    } else {
      f.seen = false;  // a dropout restarts the clock: its own fault says why
    }
  });

  if (position_ok) {
    const std::int64_t stamp = in.position.timestamp.count();
    const std::int64_t previous_stamp = last_position_stamp_ns_;
    const bool fresh = stamp != previous_stamp;
    stale_cycles_ = fresh ? 0 : stale_cycles_ + 1;
    last_position_stamp_ns_ = stamp;
    if (stale_cycles_ >= params_.encoder_stale_cycles) {
      set_condition(FaultReason::encoder_stale, FaultSignal::position, ok, stale_cycles_,
                    params_.encoder_stale_cycles);
    }
    if (fresh && have_position_) {
      // What the rod can travel between the two samples at its speed bound, plus the margin.
      // Timestamps that do not advance allow the margin alone.
      const double dt_s = static_cast<double>(std::max<std::int64_t>(0, stamp - previous_stamp)) * 1e-9;
      const double allowed = std::isfinite(params_.max_speed_m_s)
                                 ? params_.max_speed_m_s * dt_s + params_.encoder_jump_max_m
                                 : params_.encoder_jump_max_m;
      const double jump = std::abs(in.position.value - last_position_m_);
      if (jump > allowed) {
        set_condition(FaultReason::encoder_jump, FaultSignal::position, ok, jump, allowed);
      }
    }
    last_position_m_ = in.position.value;
    have_position_ = true;

    const double x = in.position.value;
    inside_soft_limits_ = x >= params_.soft_limit_low_m && x <= params_.soft_limit_high_m;
    if (x < params_.soft_limit_low_m) {
      set_condition(FaultReason::soft_limit, FaultSignal::position, ok, x,
                    params_.soft_limit_low_m);
    } else if (x > params_.soft_limit_high_m) {
      set_condition(FaultReason::soft_limit, FaultSignal::position, ok, x,
                    params_.soft_limit_high_m);
    }
  } else {
    // After a dropout the first good sample is not compared with the last one before it.
    have_position_ = false;
    stale_cycles_ = 0;
    inside_soft_limits_ = false;  // unknown: not a reason to arm
  }

  if (pa_ok && in.pressure_a.value > params_.pressure_max_pa) {
    set_condition(FaultReason::over_pressure, FaultSignal::pressure_a, ok, in.pressure_a.value,
                  params_.pressure_max_pa);
  }
  if (pb_ok && in.pressure_b.value > params_.pressure_max_pa) {
    set_condition(FaultReason::over_pressure, FaultSignal::pressure_b, ok, in.pressure_b.value,
                  params_.pressure_max_pa);
  }

  const bool driving = state_ == AxisState::enabled;
  const bool following =
      driving && mode_ == ControlMode::position && position_ok &&
      !(std::abs(in.following_error_m) <= params_.following_error_max_m);  // NaN counts as over
  following_cycles_ = following ? following_cycles_ + 1 : 0;
  if (following_cycles_ >= params_.following_error_cycles && following) {
    set_condition(FaultReason::following_error, FaultSignal::position, ok,
                  std::abs(in.following_error_m), params_.following_error_max_m);
  }
  saturated_cycles_ = driving && in.command_saturated ? saturated_cycles_ + 1 : 0;
  if (saturated_cycles_ >= params_.saturation_cycles && saturated_cycles_ > 0) {
    set_condition(FaultReason::current_saturated, FaultSignal::none, ok, saturated_cycles_,
                  params_.saturation_cycles);
  }
}

void AxisSupervisor::trip(FaultReason reason, std::int64_t t_ns) noexcept {
  fault_ = conditions_[static_cast<std::size_t>(reason)];
  fault_.t_ns = t_ns;
  ++faults_tripped_;
  following_cycles_ = 0;
  saturated_cycles_ = 0;
  holding_ = false;
}

void AxisSupervisor::output_not_finite(double command, std::int64_t t_ns) noexcept {
  if (state_ != AxisState::enabled) return;
  active_ |= bit(FaultReason::control_output);
  conditions_[static_cast<std::size_t>(FaultReason::control_output)] = {
      FaultReason::control_output, FaultSignal::none, io::SampleStatus::ok, command, 0.0, 0};
  trip(FaultReason::control_output, t_ns);
  state_ = AxisState::fault;
}

FaultReason AxisSupervisor::persistent_cause() const noexcept {
  return first_of(active_ & kPersistent);
}

void AxisSupervisor::refuse(Refusal why, FaultReason blocking) noexcept {
  last_command_.accepted = false;
  last_command_.refusal = why;
  last_command_.blocking = blocking;
  ++commands_refused_;
}

void AxisSupervisor::stop_excitation() noexcept {
  if (!excitation_.active()) return;
  excitation_.stop();
  // Hold the working point as setpoint silence holds a position: the next setpoint is followed.
  hold_position_m_ = excitation_.working_point_m();
  holding_ = true;
  setpoint_since_enable_ = false;
}

bool AxisSupervisor::handle(const AxisCommand& cmd, std::int64_t t_ns) noexcept {
  last_command_ = {cmd.seq, cmd.ticket, cmd.kind, true, Refusal::none, FaultReason::none};
  // A MODE command or a disable ends a running excitation; a move or another excitation ends it
  // when it starts (a refused one changes nothing).
  if (cmd.kind == CommandKind::set_mode || cmd.kind == CommandKind::disable) stop_excitation();
  switch (cmd.kind) {
    case CommandKind::none:
      return false;
    case CommandKind::enable:
      if (state_ == AxisState::init) {
        refuse(Refusal::starting);
      } else if (state_ == AxisState::fault) {
        refuse(Refusal::reset_first);
      } else if (state_ == AxisState::estop) {
        refuse(Refusal::estop_active);
      } else if (state_ == AxisState::disabled) {
        state_ = AxisState::enabled;
        setpoint_since_enable_ = false;  // a setpoint sent before enable is not followed
        holding_ = false;
        soft_limits_armed_ = inside_soft_limits_;  // outside: recover first
        return true;
      }
      return false;  // already enabled: accepted, nothing to do
    case CommandKind::disable:
      if (state_ == AxisState::enabled) state_ = AxisState::disabled;
      return false;  // disabling a safe axis is harmless: accepted
    case CommandKind::reset:
      if (state_ == AxisState::init) {
        refuse(Refusal::starting);
      } else if (state_ == AxisState::estop && (active_ & bit(FaultReason::estop))) {
        refuse(Refusal::estop_pressed, FaultReason::estop);
      } else if (state_ == AxisState::fault || state_ == AxisState::estop) {
        if (const FaultReason cause = persistent_cause(); cause != FaultReason::none) {
          refuse(Refusal::cause_present, cause);
        } else {
          state_ = AxisState::disabled;
          fault_ = {};
        }
      }
      return false;
    case CommandKind::move_to:
      start_move(cmd.move, t_ns);
      return false;  // the move starts where the setpoint is: nothing jumps
    case CommandKind::set_mode: {
      const bool changed = cmd.mode != mode_;
      if (changed) {
        mode_ = cmd.mode;
        // The last setpoint meant something else in the old mode: hold until a new one arrives.
        setpoint_since_enable_ = false;
        holding_ = false;
      }
      // The opening the command carries is the open loop's setpoint from this cycle on.
      if (cmd.has_opening && mode_ == ControlMode::open_loop) {
        take_setpoint(cmd.opening, 0.0, t_ns);
        if (cmd.opening_duration_s > 0.0) {
          opening_timed_ = true;
          opening_ends_ns_ = t_ns + std::llround(cmd.opening_duration_s * 1e9);
        }
      }
      return changed && state_ == AxisState::enabled;
    }
    case CommandKind::excite:
      start_excitation(cmd.excite, t_ns);
      return false;  // the loop switches to the excitation's P gain itself (Decision::exciting)
    case CommandKind::capture:
      return false;  // the flight recorder's (DaemonCycle hands it over): nothing for the state machine
    case CommandKind::gains:
      return false;  // the operator thread's (AxisLoop::request_gains): nothing for the state machine
  }
  return false;
}

void AxisSupervisor::take_setpoint(double target, double velocity_m_s, std::int64_t t_ns) noexcept {
  // The stream's own pace, for a stream that gives no velocity (hsactl sine, a program streaming
  // positions): the limiter follows a target it knows to be moving without lagging it.
  const double since_s = static_cast<double>(t_ns - last_setpoint_ns_) * 1e-9;
  stream_pace_m_s_ = setpoints_received_ > 0 && since_s > 0.0 && std::isfinite(target - target_)
                         ? (target - target_) / since_s
                         : 0.0;
  target_ = target;
  target_velocity_m_s_ = velocity_m_s;
  moving_ = false;  // a streamed setpoint takes over from a move
  excitation_.stop();  // and from an excitation
  opening_timed_ = false;  // and from a timed opening
  last_setpoint_ns_ = t_ns;
  ++setpoints_received_;
  if (state_ == AxisState::enabled) setpoint_since_enable_ = true;
}

MoveBounds move_bounds(const SupervisorParams& p) noexcept {
  const double speed = std::min(p.move_speed_m_s, p.max_speed_m_s);
  MoveBounds b;
  b.accel_m_s2 = std::isfinite(p.max_accel_m_s2) ? p.max_accel_m_s2 : speed / safety_defaults::kDefaultRampS;
  b.jerk_m_s3 = std::isfinite(p.max_jerk_m_s3) ? p.max_jerk_m_s3 : b.accel_m_s2 / safety_defaults::kDefaultJerkRampS;
  return b;
}

void AxisSupervisor::start_move(const MoveRequest& move, std::int64_t t_ns) noexcept {
  if (state_ != AxisState::enabled) return refuse(Refusal::not_enabled);
  if (mode_ != ControlMode::position) return refuse(Refusal::not_position_mode);
  if (!(move.target_m >= params_.soft_limit_low_m && move.target_m <= params_.soft_limit_high_m)) {
    return refuse(Refusal::target_outside_limits);
  }
  const double start = holding_ ? hold_position_m_ : last_rod_setpoint_m_;
  // The plant follows each direction differently (the load's weight helps one, the pump caps the
  // other): the move is bounded by the one it travels. A move of no distance travels neither way
  // that matters; it is judged as extending.
  const Travel travel = move.target_m < start ? Travel::retract : Travel::extend;
  const DirectionLimit& plant = params_.capability.of(travel);
  const bool extending = travel == Travel::extend;
  // No speed asked: the axis's, slowed to what the plant follows this way.
  const double speed = move.speed_m_s > 0.0
                           ? move.speed_m_s
                           : std::min({params_.move_speed_m_s, params_.max_speed_m_s, plant.speed_m_s});
  if (!std::isfinite(speed) || speed > params_.max_speed_m_s) return refuse(Refusal::speed_over_limit);
  if (speed > plant.speed_m_s) {
    return refuse(extending ? Refusal::speed_over_extend_capability : Refusal::speed_over_retract_capability);
  }
  const MoveBounds bounds = move_bounds(params_);
  if (move.accel_m_s2 > bounds.accel_m_s2) return refuse(Refusal::accel_over_limit);
  if (move.accel_m_s2 > plant.accel_m_s2) {
    return refuse(extending ? Refusal::accel_over_extend_capability : Refusal::accel_over_retract_capability);
  }
  const double accel = move.accel_m_s2 > 0.0 ? move.accel_m_s2 : std::min(bounds.accel_m_s2, plant.accel_m_s2);
  // A target on a soft limit is planned to the setpoint band's edge (kSoftLimitSetpointMarginM).
  const SetpointBand band = setpoint_band(params_);
  move_ = control::JerkLimitedProfile(start, std::clamp(move.target_m, band.low_m, band.high_m),
                                      {speed, accel, bounds.jerk_m_s3});
  move_start_ns_ = t_ns;
  excitation_.stop();  // the move starts from the excitation's setpoint of the last cycle
  moving_ = true;
  holding_ = false;
  setpoint_since_enable_ = true;  // a move is a new setpoint: it re-arms the soft limits too
}

void AxisSupervisor::start_excitation(const ExcitationRequest& request, std::int64_t t_ns) noexcept {
  if (state_ != AxisState::enabled) return refuse(Refusal::not_enabled);
  if (mode_ != ControlMode::position) return refuse(Refusal::not_position_mode);
  const double low = request.working_point_m - request.amplitude_m;
  const double high = request.working_point_m + request.amplitude_m;
  if (!(low >= params_.soft_limit_low_m && high <= params_.soft_limit_high_m)) {
    return refuse(Refusal::excitation_outside_limits);
  }
  if (!excitation_.start(request, t_ns)) return refuse(Refusal::excitation_invalid);  // the old one runs on
  ++excitations_started_;  // a new run, even one replacing another: the loop starts it afresh
  moving_ = false;
  holding_ = false;
  setpoint_since_enable_ = true;  // a new setpoint: it re-arms the soft limits too, as a move does
}

Decision AxisSupervisor::update(const SupervisorInputs& in,
                                const AxisInputsFromOperator& op) noexcept {
  evaluate(in);
  Decision d;
  if (!updated_) {
    updated_ = true;
    first_update_ns_ = in.t_ns;
  }
  const Missing missing = state_ == AxisState::init ? first_missing(in) : Missing{};
  const bool starting = missing.signal != FaultSignal::none;
  if (starting) {
    // Only what needs no input, and an e-stop that reads asserted, count yet.
    const bool estop_asserted = in.has_estop && in.estop.ok() && in.estop.value;
    active_ &= kJudgedWhileStarting | (estop_asserted ? bit(FaultReason::estop) : 0u);
    const std::int64_t waited_ns = in.t_ns - first_update_ns_;
    if (active_ == 0 && waited_ns >= params_.startup_timeout_ns) {
      set_condition(FaultReason::inputs_not_ready, missing.signal, missing.status,
                    static_cast<double>(waited_ns) * 1e-9, static_cast<double>(params_.startup_timeout_ns) * 1e-9);
    }
  }

  if (active_ & bit(FaultReason::estop)) {
    // A latched FAULT keeps its first cause: the valve is already safe, and an e-stop that
    // reads pressed or unreadable now (a bus being recovered reads nothing yet) blocks the reset
    // as a present cause instead of hiding why the axis faulted.
    if (state_ != AxisState::estop && state_ != AxisState::fault) {
      trip(FaultReason::estop, in.t_ns);
      state_ = AxisState::estop;
      d.tripped = true;
    }
  } else if (state_ == AxisState::init || state_ == AxisState::disabled ||
             state_ == AxisState::enabled) {
    std::uint32_t trips = state_ == AxisState::enabled ? active_ : active_ & ~kEnabledOnly;
    if (!soft_limits_armed_) trips &= ~bit(FaultReason::soft_limit);
    if (const FaultReason r = first_of(trips); r != FaultReason::none) {
      trip(r, in.t_ns);
      state_ = AxisState::fault;
      d.tripped = true;
    } else if (state_ == AxisState::init && !starting) {
      state_ = AxisState::disabled;
    }
  }

  if (op.setpoint.seq != last_setpoint_seq_) {
    last_setpoint_seq_ = op.setpoint.seq;
    take_setpoint(op.setpoint.target, op.setpoint.velocity_m_s, in.t_ns);
  }
  if (op.command.seq != last_command_seq_) {
    last_command_seq_ = op.command.seq;
    d.activate = handle(op.command, in.t_ns);
  }

  d.state = state_;
  d.mode = mode_;
  if (state_ != AxisState::enabled || mode_ != ControlMode::position) {
    moving_ = false;
    excitation_.stop();  // a fault, an e-stop: nothing to hold
  }
  if (excitation_.active() && excitation_.over(in.t_ns)) stop_excitation();  // holds the working point
  if (state_ != AxisState::enabled || mode_ != ControlMode::open_loop) opening_timed_ = false;
  if (opening_timed_ && in.t_ns >= opening_ends_ns_) {
    opening_timed_ = false;
    target_ = 0.0;  // ended by the axis: opening 0 until the next opening
  }
  // Unless this cycle follows the stream, the next streamed setpoint starts the limiter afresh.
  const bool stream_limiter_was_live = stream_limiter_live_;
  stream_limiter_live_ = false;
  if (state_ != AxisState::enabled) {
    holding_ = false;
    return d;
  }
  d.drive = true;
  const SetpointBand band = setpoint_band(params_);
  if (!soft_limits_armed_ && inside_soft_limits_ && setpoint_since_enable_) soft_limits_armed_ = true;
  if (excitation_.active()) {
    d.rod_setpoint_m =
        std::clamp(excitation_.setpoint(in.t_ns), band.low_m, band.high_m);
    d.exciting = true;
    d.excitation = excitations_started_;
    d.excite_kp_per_m = excitation_.kp_per_m();
    last_rod_setpoint_m_ = d.rod_setpoint_m;
    last_velocity_ff_m_s_ = 0.0;  // its levels step: no velocity to carry into a stream
    return d;
  }
  if (moving_) {
    const double t_s = static_cast<double>(in.t_ns - move_start_ns_) * 1e-9;
    const control::MotionSample m = move_.at(t_s);
    d.rod_setpoint_m = std::clamp(m.position_m, band.low_m, band.high_m);
    d.velocity_ff_m_s = m.velocity_m_s;
    d.accel_ff_m_s2 = m.accel_m_s2;
    d.jerk_ff_m_s3 = m.jerk_m_s3;
    d.move_under_way = t_s < move_.duration_s();
    d.setpoint_planned = d.move_under_way;
    last_rod_setpoint_m_ = d.rod_setpoint_m;
    last_velocity_ff_m_s_ = d.velocity_ff_m_s;  // a stream that takes over mid-move goes on from here
    return d;
  }
  const bool fresh = setpoint_since_enable_ &&
                     (opening_timed_ || in.t_ns - last_setpoint_ns_ <= params_.setpoint_timeout_ns) &&
                     std::isfinite(target_);
  if (!fresh && !holding_) {
    // Hold where the rod is now; with no usable position we would have faulted already.
    hold_position_m_ = in.position.value;
  }
  holding_ = !fresh;
  d.holding = holding_;
  if (mode_ == ControlMode::position) {
    const double target = holding_ ? hold_position_m_ : target_;
    d.rod_setpoint_m = std::clamp(target, band.low_m, band.high_m);
    d.velocity_ff_m_s = holding_ ? 0.0 : target_velocity_m_s_;
    if (!holding_ && limit_streams_) {
      // The stream through the limiter, from the last rod setpoint on (no bump). A velocity the
      // stream does not give as a number is no velocity: the target is followed all the same.
      if (!stream_limiter_was_live) {
        stream_limiter_.reset(last_rod_setpoint_m_, last_velocity_ff_m_s_);
        stream_accel_m_s2_ = 0.0;
      }
      // The velocity the stream gives, or its pace when it gives none (0).
      const double given = std::isfinite(target_velocity_m_s_) ? target_velocity_m_s_ : 0.0;
      const double target_velocity = given != 0.0 ? given : stream_pace_m_s_;
      const double dt_s = static_cast<double>(in.cycle_gap_ns) * 1e-9;
      if (stream_limiter_.step(d.rod_setpoint_m, target_velocity, dt_s)) {
        stream_accel_m_s2_ += dt_s / (kStreamAccelFilterS + dt_s) * (stream_limiter_.accel_m_s2() - stream_accel_m_s2_);
      }
      stream_limiter_live_ = true;
      d.rod_setpoint_m = stream_limiter_.position_m();
      d.velocity_ff_m_s = stream_limiter_.velocity_m_s();
      d.accel_ff_m_s2 = stream_accel_m_s2_;
      // Lagging the stream, the limiter plans the setpoint's path itself, as a move's profile
      // does: the PI holds its integrator for the same reason (pi_controller.hpp), so that what
      // the feed-forward misses on the way is not released as overshoot where the limiter stops.
      d.setpoint_planned = std::abs(stream_limiter_.lag_m()) > kSlowedSetpointM;
      if (d.setpoint_planned) ++setpoint_cycles_limited_;
    }
    last_rod_setpoint_m_ = d.rod_setpoint_m;
    last_velocity_ff_m_s_ = d.velocity_ff_m_s;
  } else {
    // Recovering from outside the soft limits: no opening, as the supervisor cannot tell which
    // sign moves the rod inward.
    d.opening = holding_ || !soft_limits_armed_ ? 0.0 : std::clamp(target_, -1.0, 1.0);
  }
  return d;
}

}  // namespace hsa::daemon
