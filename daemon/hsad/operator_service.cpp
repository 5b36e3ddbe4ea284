#include "daemon/hsad/operator_service.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "daemon/hsad/wire_state.hpp"

namespace hsa::daemon {
namespace {

MsgFaultCode code_of(FaultReason r) {
  switch (r) {
    case FaultReason::estop: return MsgFaultCode::estop;
    case FaultReason::driver_error: return MsgFaultCode::driver;
    case FaultReason::rt_overruns: return MsgFaultCode::overruns;
    case FaultReason::sensor_not_ok: return MsgFaultCode::sensor;
    case FaultReason::encoder_stale:
    case FaultReason::encoder_jump: return MsgFaultCode::encoder;
    case FaultReason::over_pressure: return MsgFaultCode::pressure;
    case FaultReason::soft_limit: return MsgFaultCode::soft_limit;
    case FaultReason::following_error: return MsgFaultCode::following_error;
    case FaultReason::current_saturated: return MsgFaultCode::current_saturation;
    case FaultReason::none: break;
  }
  return MsgFaultCode::sensor;
}


}  // namespace

OperatorService::OperatorService(std::vector<std::unique_ptr<AxisRuntime>>& axes, const RtExecutive& executive,
                                 const RtConfig& rt, const RealtimeGrant& grant)
    : axes_(axes), executive_(executive), rt_(rt), grant_(grant), latest_(axes.size()) {}

void OperatorService::handle_commands(AxisRuntime& axis) {
  CommandMsg c;
  while (axis.port.pop_command(c)) {
    ForwardedCommand fc;
    switch (c.kind) {
      case MsgCommandKind::enable: fc.kind = CommandKind::enable; break;
      case MsgCommandKind::disable: fc.kind = CommandKind::disable; break;
      case MsgCommandKind::reset: fc.kind = CommandKind::reset; break;
      case MsgCommandKind::mode:
        fc.kind = CommandKind::set_mode;
        fc.mode = c.mode == MsgControlMode::valve_opening ? ControlMode::open_loop : ControlMode::position;
        fc.has_opening = c.mode == MsgControlMode::valve_opening;
        fc.opening = c.valve_opening;
        break;
      case MsgCommandKind::gains: {
        control::CascadeParams params = axis.loop->params().cascade;
        params.cylinder.kp = c.kp;
        params.cylinder.ki = c.ki;
        try {
          axis.loop->request_params(params);
        } catch (const std::exception& e) {
          ++gains_refused_;
          std::fprintf(stderr, "hsad: axis %s: gains refused: %s\n", axis.port.name().c_str(), e.what());
        }
        continue;
      }
    }
    if (!axis.commands.try_push(fc))
      std::fprintf(stderr, "hsad: axis %s: command ring full, command dropped\n", axis.port.name().c_str());
  }
}

StatusSample OperatorService::status_of(const AxisTelemetry& tm, const RtStats& rt) const {
  StatusSample s;
  s.utime = tm.t_ns / 1000;
  s.state = to_wire(tm.state);
  s.mode = tm.mode == ControlMode::open_loop ? MsgControlMode::valve_opening : MsgControlMode::position;
  s.holding = tm.holding;
  if (tm.fault.reason != FaultReason::none) {
    s.num_faults = 1;
    s.faults[0].code = code_of(tm.fault.reason);
    const std::string text = describe(tm.fault);
    std::snprintf(s.faults[0].reason, FaultEntry::kReasonSize, "%s", text.c_str());
  }
  s.rt_overruns = static_cast<std::int64_t>(rt.overruns);
  s.rt_allocations = static_cast<std::int64_t>(rt.steady_allocations);
  s.rt_locks = static_cast<std::int64_t>(rt.steady_locks);
  s.rt_minor_faults = static_cast<std::int64_t>(rt.steady_minor_faults);
  s.rt_major_faults = static_cast<std::int64_t>(rt.steady_major_faults);
  s.sched_fifo = grant_.sched_fifo;
  s.memory_locked = grant_.memory_locked;
  s.rt_priority = static_cast<std::int16_t>(grant_.sched_fifo ? rt_.priority : 0);
  s.rt_cpu = static_cast<std::int16_t>(grant_.affinity ? rt_.cpu : -1);
  return s;
}

void OperatorService::poll() {
  const RtStats rt = executive_.snapshot();
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    AxisRuntime& axis = *axes_[i];
    handle_commands(axis);
    if (const AxisTelemetry* tm = axis.latest.take()) latest_[i] = *tm;
    (void)axis.port.push_status(status_of(latest_[i], rt));
  }
}

}  // namespace hsa::daemon
