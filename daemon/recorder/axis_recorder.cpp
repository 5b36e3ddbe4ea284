#include "daemon/recorder/axis_recorder.hpp"

namespace hsa::daemon {

void fill_row(RecorderRow& r, const AxisTelemetry& tm, double limited_setpoint_m, double integral,
              std::uint64_t seq, std::uint64_t tick, std::uint64_t skipped, std::int32_t lateness_ns) noexcept {
  r.seq = seq;
  r.tick = tick;
  r.skipped = skipped;
  r.t_ns = tm.t_ns;
  r.setpoint = tm.setpoint;
  r.rod_setpoint_m = limited_setpoint_m;
  r.position_m = tm.position_m;
  r.velocity_m_s = tm.velocity_m_s;
  r.following_error_m = tm.following_error_m;
  r.opening = tm.opening;
  r.command = tm.command;
  r.spool_m = tm.spool_position_m;
  r.pressure_a_pa = tm.pressure_a_pa;
  r.pressure_b_pa = tm.pressure_b_pa;
  r.integral = integral;
  r.active_faults = tm.active_faults;
  r.lateness_ns = lateness_ns;
  r.exec_ns = 0;  // AxisRecorder::commit() writes it
  r.state = static_cast<std::uint8_t>(tm.state);
  r.mode = static_cast<std::uint8_t>(tm.mode);
  r.valve_enabled = tm.valve_enabled ? 1 : 0;
  r.fault_reason = static_cast<std::uint8_t>(tm.fault.reason);
}

void AxisRecorder::record(const AxisLoop& loop, std::uint64_t tick, std::uint64_t skipped,
                          std::int32_t lateness_ns) noexcept {
  const AxisTelemetry& tm = loop.telemetry();
  const control::ControlLaw& law = loop.law();
  fill_row(ring_->slot(), tm, law.limited_setpoint_m(), law.integral(), rows_++, tick, skipped, lateness_ns);

  kp_ = tm.kp;
  ki_ = tm.ki;
  fault_ = tm.fault;
  const bool tripped = (tm.state == AxisState::fault || tm.state == AxisState::estop) && tm.state != last_state_;
  last_state_ = tm.state;
  const bool manual = ring_->take_manual_request();
  const bool requested = manual || now_pending_;
  if (tripped || requested) {
    // A fault takes its own window; a request in the same cycle falls into it (merged below).
    CaptureTrigger why{.kind = tripped ? TriggerKind::fault : TriggerKind::request,
                       .state = tm.state,
                       .fault = tm.fault,
                       .tick = tick,
                       .t_ns = tm.t_ns,
                       .kp = tm.kp,
                       .ki = tm.ki};
    if (!tripped && now_pending_) {
      why.pre_rows = now_.pre_rows;
      why.post_rows = now_.post_rows;
    }
    ring_->trigger(why);
    if (tripped && requested) ring_->trigger(why);  // counted: merged into the fault's capture
  }
  now_pending_ = false;
}

void AxisRecorder::apply(const CaptureRequest& request, std::uint64_t ticket) noexcept {
  switch (request.action) {
    case CaptureAction::now:
      now_pending_ = true;
      now_ = request;
      break;
    case CaptureAction::arm:
      condition_.arm({.signal = request.signal_index,
                      .crossing = request.crossing,
                      .level = request.level,
                      .repeat = request.repeat});
      condition_pre_ = request.pre_rows;
      condition_post_ = request.post_rows;
      armed_ticket_.store(condition_.armed() ? ticket : 0, std::memory_order_relaxed);
      break;
    case CaptureAction::disarm:
      condition_.disarm();
      armed_ticket_.store(0, std::memory_order_relaxed);
      break;
  }
}

void AxisRecorder::commit(std::int32_t exec_ns) noexcept {
  RecorderRow& row = ring_->slot();
  row.exec_ns = exec_ns;
  if (condition_.armed() && condition_.evaluate(row)) {
    const ConditionSpec& c = condition_.spec();
    ring_->trigger({.kind = TriggerKind::condition,
                    .state = static_cast<AxisState>(row.state),
                    .fault = fault_,
                    .tick = row.tick,
                    .t_ns = row.t_ns,
                    .kp = kp_,
                    .ki = ki_,
                    .pre_rows = condition_pre_,
                    .post_rows = condition_post_,
                    .signal = c.signal,
                    .crossing = c.crossing,
                    .level = c.level});
    if (!condition_.armed()) armed_ticket_.store(0, std::memory_order_relaxed);  // single-shot: done
  }
  ring_->commit();
}

}  // namespace hsa::daemon
