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

  const bool tripped = (tm.state == AxisState::fault || tm.state == AxisState::estop) && tm.state != last_state_;
  last_state_ = tm.state;
  const bool manual = ring_->take_manual_request();
  if (tripped || manual) {
    ring_->trigger({.kind = tripped ? TriggerKind::fault : TriggerKind::manual,
                    .state = tm.state,
                    .fault = tm.fault,
                    .tick = tick,
                    .t_ns = tm.t_ns,
                    .kp = tm.kp,
                    .ki = tm.ki});
  }
}

}  // namespace hsa::daemon
