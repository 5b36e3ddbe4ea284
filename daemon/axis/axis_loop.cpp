#include "daemon/axis/axis_loop.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <stdexcept>
#include <utility>

namespace hsa::daemon {

namespace {

std::unique_ptr<control::ControlLaw> law_of(const AxisParams& p) {
  if (!p.law) throw std::invalid_argument("axis '" + p.name + "': no control law");
  return p.law->clone();
}

// Refuses an unbound input that the table requires, or that the law closes its valve loop on.
void refuse_unbound(const AxisParams& p, const control::ControlLaw& law, AxisInput which) {
  const AxisInputInfo& input = info(which);
  if (input.presence == InputPresence::required) {
    throw std::invalid_argument("axis '" + p.name + "': no " + std::string(input.key) + " signal");
  }
  if (input.presence == InputPresence::law && law.needs_spool()) {
    throw std::invalid_argument("axis '" + p.name + "': drive \"" + std::string(law.name()) + "\" needs a " +
                                std::string(input.key) + " signal");
  }
}

}  // namespace

AxisLoop::AxisLoop(const AxisParams& params, AxisSignals signals)
    : params_(params),
      signals_(std::move(signals)),
      supervisor_(params.safety, params.initial_mode),
      law_(law_of(params)),
      pending_(law_->gains()) {
#define HSA_REQUIRE_INPUT(signal, name, kind, presence, unreadable) \
  if (!signals_.signal) refuse_unbound(params, *law_, AxisInput::signal);
  HSA_AXIS_INPUTS(HSA_REQUIRE_INPUT)
#undef HSA_REQUIRE_INPUT
  if (!(params.velocity_filter_s >= 0.0)) {
    throw std::invalid_argument("axis '" + params.name + "': velocity_filter_s must be >= 0");
  }
  drive_safe();
}

void AxisLoop::request_gains(const control::RuntimeGains& gains) {
  try {
    law_->check_gains(gains);  // reads only the law's immutable bounds and gain gate: safe on this thread
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("axis '" + params_.name + "': " + e.what());
  }
  pending_.publish(gains);
}

void AxisLoop::drive_safe() noexcept {
  (void)signals_.valve_command.set(params_.safe_command);
  signals_.valve_enable.set(false);
  applied_opening_ = 0.0;
}

void AxisLoop::activate(double position_m, double spool_m, double opening) noexcept {
  law_->activate(position_m, spool_m, opening);
}

void AxisLoop::apply_pending_gains() noexcept {
  const control::RuntimeGains* g = pending_.take();
  if (g == nullptr) return;
  if (exciting_) {
    // The operator's new gains end the excitation; they are the ones restored when it does.
    gains_after_excitation_ = *g;
    supervisor_.stop_excitation();
    ++param_changes_;
    return;
  }
  // Checked by request_gains(); the law keeps every other state, so nothing is re-activated.
  law_->set_gains(*g);
  ++param_changes_;
}

void AxisLoop::follow_excitation(const Decision& d, double position_m, double spool_m) noexcept {
  if (d.exciting && (!exciting_ || d.excitation != excitation_)) {
    if (!exciting_) gains_after_excitation_ = law_->gains();  // not those of the run it replaces
    excitation_ = d.excitation;
    law_->activate(position_m, spool_m, 0.0);  // integral 0: the opening is kp·e from here
    law_->set_gains({.kp = d.excite_kp_per_m, .ki = 0.0});
    exciting_ = true;
  } else if (!d.exciting && exciting_) {
    law_->set_gains(gains_after_excitation_);  // bumpless: the integral takes up the last output
    exciting_ = false;
  }
}

void AxisLoop::cycle(std::int64_t t_ns, const AxisInputsFromOperator& op,
                     const ExecutiveInputs& executive, std::uint64_t tick) noexcept {
  if (tick == kNextTick) tick = have_cycle_ ? last_tick_ + 1 : 0;
  const std::int64_t cycle_gap_ns = have_cycle_ && !executive.final_cycle ? t_ns - last_cycle_ns_ : 0;
  have_cycle_ = true;
  last_cycle_ns_ = t_ns;
  last_tick_ = tick;

  SupervisorInputs in;
  // An unbound input reads as never delivered (value 0), and is not judged.
#define HSA_READ_INPUT(signal, name, kind, presence, unreadable) \
  in.has_##signal = signals_.signal.has_value();                  \
  if (signals_.signal) in.signal = signals_.signal->sample();
  HSA_AXIS_INPUTS(HSA_READ_INPUT)
#undef HSA_READ_INPUT
  const io::AnalogSample& position = in.position;
  const io::AnalogSample& pressure_a = in.pressure_a;
  const io::AnalogSample& pressure_b = in.pressure_b;
  const io::AnalogSample& spool = in.spool;

  apply_pending_gains();

  in.t_ns = t_ns;
  in.cycle_gap_ns = cycle_gap_ns;
  // Only a PI that ran last cycle has a setpoint to follow (the mode is still last cycle's here).
  in.following_error_m = driving_ && supervisor_.mode() == ControlMode::position
                              ? law_->limited_setpoint_m() - position.value
                              : 0.0;
  in.command_saturated = last_saturated_;
  in.executive = executive;
  Decision d = supervisor_.update(in, op);

  follow_excitation(d, position.value, spool.value);

  control::LawOutput out{};
  bool saturated = false;
  if (!d.drive) {
    drive_safe();
    driving_ = false;
  } else {
    if (d.activate || !driving_) activate(position.value, spool.value, applied_opening_);
    if (d.mode == ControlMode::position) {
      out = law_->tick({d.rod_setpoint_m, position.value, spool.value, d.velocity_ff_m_s, d.accel_ff_m_s2, d.jerk_ff_m_s3,
                        d.setpoint_planned},
                       tick);
      saturated = law_->saturated();
    } else {
      out = law_->open_loop_tick(d.opening, spool.value, tick);
    }
    if (!std::isfinite(out.command) || !std::isfinite(out.opening)) {
      // No NaN reaches an output: fault now, valve safe now. The loops are re-activated from the
      // measured state at the next enable, which clears whatever state went non-finite.
      supervisor_.output_not_finite(std::isfinite(out.command) ? out.opening : out.command, t_ns);
      d.state = supervisor_.state();
      d.drive = false;
      d.tripped = true;
      drive_safe();
      driving_ = false;
      out = {};
      saturated = false;
    } else {
      const io::AnalogOutputState written = signals_.valve_command.set(out.command);
      signals_.valve_enable.set(true);
      saturated = saturated || written.saturated;
      applied_opening_ = out.opening;
      driving_ = true;
    }
  }
  last_saturated_ = saturated;

  // Rod velocity from successive encoder samples, low-pass filtered against quantization.
  if (position.ok()) {
    const std::int64_t stamp = position.timestamp.count();
    if (have_velocity_sample_ && stamp > last_position_stamp_ns_) {
      const double dt = static_cast<double>(stamp - last_position_stamp_ns_) * 1e-9;
      const double raw = (position.value - last_position_m_) / dt;
      velocity_m_s_ += dt / (params_.velocity_filter_s + dt) * (raw - velocity_m_s_);
    }
    if (!have_velocity_sample_ || stamp != last_position_stamp_ns_) {
      last_position_m_ = position.value;
      last_position_stamp_ns_ = stamp;
    }
    have_velocity_sample_ = true;
  } else {
    have_velocity_sample_ = false;
    velocity_m_s_ = 0.0;
  }

  AxisTelemetry& tm = telemetry_;
  tm.t_ns = t_ns;
  ++tm.cycle;
  tm.setpoint_utime = op.setpoint.utime;
  tm.setpoint = d.mode == ControlMode::position ? d.rod_setpoint_m : d.opening;
  // An excitation's record is the P loop's input and output: the setpoint its error is taken from
  // (after the rate limit, which spreads a level change over a few samples), so that the opening is
  // kp·(setpoint − position) sample by sample, as identification models the run.
  if (d.exciting && d.drive) tm.setpoint = law_->limited_setpoint_m();
  tm.position_m = position.value;
  tm.velocity_m_s = velocity_m_s_;
  tm.pressure_a_pa = pressure_a.value;
  tm.pressure_b_pa = pressure_b.value;
  tm.pressure_load_pa = pressure_a.value - params_.area_ratio * pressure_b.value;
  tm.opening = d.drive ? out.opening : 0.0;
  tm.spool_position_m = signals_.spool ? spool.value : 0.0;
  tm.command = signals_.valve_command.state().value;
  tm.valve_enabled = signals_.valve_enable.value();
  tm.following_error_m = d.drive && d.mode == ControlMode::position
                             ? law_->limited_setpoint_m() - position.value
                             : 0.0;
  const std::int64_t stale_ns = params_.safety.input_stale_ns;
  // An input the axis has no binding for reads as having none (age -1), not as stale.
#define HSA_INPUT_AGE(signal, name, kind, presence, unreadable)                 \
  tm.inputs[static_cast<std::size_t>(FaultSignal::signal) - 1] =              \
      in.has_##signal ? input_age(in.signal, t_ns, stale_ns) : InputAge{};
  HSA_AXIS_INPUTS(HSA_INPUT_AGE)
#undef HSA_INPUT_AGE
  tm.estop = in.has_estop && in.estop.value;
  tm.state = d.state;
  tm.mode = d.mode;
  tm.holding = d.holding;
  tm.exciting = d.exciting;
  tm.fault = supervisor_.fault();
  tm.active_faults = supervisor_.active_faults();
  tm.last_command = supervisor_.last_command();
  tm.param_changes_applied = param_changes_;
  const control::RuntimeGains gains = law_->gains();
  tm.kp = gains.kp;
  tm.ki = gains.ki;
}

}  // namespace hsa::daemon
