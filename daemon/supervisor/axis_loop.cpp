#include "daemon/supervisor/axis_loop.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <stdexcept>
#include <utility>

namespace hsa::daemon {

namespace {

GainBounds bounds_of(const AxisParams& p) {
  return p.gain_bounds ? *p.gain_bounds : default_gain_bounds(p.cascade.cylinder);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

AxisLoop::AxisLoop(const AxisParams& params, AxisSignals signals)
    : params_(params),
      gain_bounds_(bounds_of(params)),
      signals_(std::move(signals)),
      supervisor_(params.safety, params.initial_mode),
      cascade_(params.cascade),
      open_predictor_(params.cascade.predictor, params.cascade.valve.period_s),
      open_law_(params.cascade.valve),
      pending_(params.cascade) {
  if (params.cascade.drive == control::ValveDrive::proportional && !signals_.spool) {
    throw std::invalid_argument("axis '" + params.name +
                                "': a proportional valve drive needs a spool signal");
  }
  const control::PiParams& pi = params.cascade.cylinder;
  if (!std::isfinite(gain_bounds_.max_kp) || !(pi.kp > 0.0) || !(pi.kp <= gain_bounds_.max_kp) ||
      !std::isfinite(gain_bounds_.max_ki) || !(pi.ki >= 0.0) || !(pi.ki <= gain_bounds_.max_ki)) {
    throw std::invalid_argument("axis '" + params.name + "': the PI gains kp " + number(pi.kp) + ", ki " +
                                number(pi.ki) + " must lie within finite bounds (0, max_kp " +
                                number(gain_bounds_.max_kp) + "] and [0, max_ki " +
                                number(gain_bounds_.max_ki) + "]");
  }
  if (!(params.velocity_filter_s >= 0.0)) {
    throw std::invalid_argument("axis '" + params.name + "': velocity_filter_s must be >= 0");
  }
  drive_safe();
}

void AxisLoop::request_params(const control::CascadeParams& p) {
  // Only the gains change at run time, so everything else must equal the configuration, which is
  // immutable and therefore safe to read on this thread.
  const control::CascadeParams& fixed = params_.cascade;
  const auto refuse = [this](const std::string& why) {
    throw std::invalid_argument("axis '" + params_.name + "': " + why);
  };
  if (p.drive != fixed.drive || p.valve_ticks_per_cylinder_tick != fixed.valve_ticks_per_cylinder_tick ||
      p.valve.period_s != fixed.valve.period_s || p.cylinder.period_s != fixed.cylinder.period_s) {
    refuse("the valve drive, loop periods and tick ratio cannot change while running");
  }
  if (!(p.valve == fixed.valve) || !(p.predictor == fixed.predictor) ||
      p.spool_at_full_opening_m != fixed.spool_at_full_opening_m) {
    refuse("the valve law and state predictor cannot change while running (only the PI's kp and ki)");
  }
  control::PiParams others = p.cylinder;
  others.kp = fixed.cylinder.kp;
  others.ki = fixed.cylinder.ki;
  if (!(others == fixed.cylinder)) {
    refuse("of the PI only kp and ki can change while running (not its speed, dead bands, output "
           "limit or feed-forward)");
  }
  const double kp = p.cylinder.kp;
  const double ki = p.cylinder.ki;
  if (!std::isfinite(kp) || !std::isfinite(ki)) refuse("the gains must be finite numbers");
  if (!(kp > 0.0) || kp > gain_bounds_.max_kp) {
    refuse("kp " + number(kp) + " is outside (0, max_kp " + number(gain_bounds_.max_kp) + "] 1/m");
  }
  if (!(ki >= 0.0) || ki > gain_bounds_.max_ki) {
    refuse("ki " + number(ki) + " is outside [0, max_ki " + number(gain_bounds_.max_ki) + "] 1/(m s)");
  }
  pending_.publish(p);
}

void AxisLoop::drive_safe() noexcept {
  (void)signals_.valve_command.set(params_.safe_command);
  signals_.valve_enable.set(false);
  applied_opening_ = 0.0;
}

void AxisLoop::activate(double position_m, double spool_m, double opening) noexcept {
  cascade_.activate(position_m, spool_m, opening);
  open_predictor_.reset(spool_m);
  open_law_.reset();
}

void AxisLoop::apply_pending_params() noexcept {
  const control::CascadeParams* p = pending_.take();
  if (p == nullptr) return;
  // Validated by request_params(): only the gains differ, and they are ones set_cylinder_gains
  // takes without throwing. It keeps every loop state, so nothing is re-activated: the opening
  // and, on a proportional valve, the predictor and valve law carry on (the open-loop path's
  // predictor and law have no gains that can change).
  cascade_.set_cylinder_gains(p->cylinder.kp, p->cylinder.ki);
  ++param_changes_;
}

void AxisLoop::cycle(std::int64_t t_ns, const AxisInputsFromOperator& op,
                     const ExecutiveInputs& executive, std::uint64_t tick) noexcept {
  if (tick == kNextTick) tick = have_cycle_ ? last_tick_ + 1 : 0;
  // Valve periods since the last cycle, for the open-loop valve path (the cascade counts its own).
  const std::uint64_t elapsed = have_cycle_ && tick > last_tick_ ? tick - last_tick_ : 1;
  const std::int64_t cycle_gap_ns = have_cycle_ && !executive.final_cycle ? t_ns - last_cycle_ns_ : 0;
  have_cycle_ = true;
  last_cycle_ns_ = t_ns;
  last_tick_ = tick;

  const io::AnalogSample position = signals_.position.sample();
  const io::AnalogSample pressure_a = signals_.pressure_a.sample();
  const io::AnalogSample pressure_b = signals_.pressure_b.sample();
  const io::AnalogSample spool =
      signals_.spool ? signals_.spool->sample() : io::AnalogSample{0.0, {}, io::SampleStatus::ok};
  const io::DigitalSample estop = signals_.estop ? signals_.estop->sample() : io::DigitalSample{};

  apply_pending_params();

  SupervisorInputs in;
  in.t_ns = t_ns;
  in.cycle_gap_ns = cycle_gap_ns;
  in.position = position;
  in.pressure_a = pressure_a;
  in.pressure_b = pressure_b;
  in.spool = spool;
  in.estop = estop;
  in.has_spool = signals_.spool.has_value();
  in.has_estop = signals_.estop.has_value();
  // Only a PI that ran last cycle has a setpoint to follow (the mode is still last cycle's here).
  in.following_error_m = driving_ && supervisor_.mode() == ControlMode::position
                              ? cascade_.cylinder().limited_setpoint() - position.value
                              : 0.0;
  in.command_saturated = last_saturated_;
  in.executive = executive;
  Decision d = supervisor_.update(in, op);

  control::CascadeOutput out{};
  bool saturated = false;
  if (!d.drive) {
    drive_safe();
    driving_ = false;
  } else {
    if (d.activate || !driving_) activate(position.value, spool.value, applied_opening_);
    if (d.mode == ControlMode::position) {
      // The setpoint's velocity feed-forward, while it is followed (not while holding).
      const double v_ff = d.holding ? 0.0 : op.setpoint.velocity_m_s;
      out = cascade_.tick({d.rod_setpoint_m, position.value, spool.value, v_ff}, tick);
      saturated = cascade_.cylinder().saturated();
    } else {
      out.opening = d.opening;
      out.spool_reference_m = d.opening * cascade_.params().spool_at_full_opening_m;
      out.command = cascade_.params().drive == control::ValveDrive::direct
                        ? d.opening
                        : open_law_.update(out.spool_reference_m,
                                           open_predictor_.update(spool.value, elapsed), elapsed);
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
  tm.setpoint_seq = op.setpoint.seq;
  tm.setpoint = d.mode == ControlMode::position ? d.rod_setpoint_m : d.opening;
  tm.limited_setpoint_m = cascade_.cylinder().limited_setpoint();
  tm.position_m = position.value;
  tm.velocity_m_s = velocity_m_s_;
  tm.pressure_a_pa = pressure_a.value;
  tm.pressure_b_pa = pressure_b.value;
  tm.pressure_load_pa = pressure_a.value - params_.area_ratio * pressure_b.value;
  tm.opening = d.drive ? out.opening : 0.0;
  tm.spool_position_m = signals_.spool ? spool.value : 0.0;
  tm.spool_reference_m = out.spool_reference_m;
  tm.command = signals_.valve_command.state().value;
  tm.command_saturated = saturated;
  tm.valve_enabled = signals_.valve_enable.value();
  tm.following_error_m = d.drive && d.mode == ControlMode::position
                             ? cascade_.cylinder().limited_setpoint() - position.value
                             : 0.0;
  tm.state = d.state;
  tm.mode = d.mode;
  tm.holding = d.holding;
  tm.fault = supervisor_.fault();
  tm.active_faults = supervisor_.active_faults();
  tm.last_command = supervisor_.last_command();
  tm.faults_tripped = supervisor_.faults_tripped();
  tm.commands_refused = supervisor_.commands_refused();
  tm.setpoints_received = supervisor_.setpoints_received();
  tm.param_changes_applied = param_changes_;
  tm.kp = cascade_.params().cylinder.kp;
  tm.ki = cascade_.params().cylinder.ki;
}

}  // namespace hsa::daemon
