#include "daemon/lcm_bridge/message_validation.hpp"

#include <cmath>

namespace hsa::daemon {

static_assert(static_cast<std::int8_t>(MsgCommandKind::enable) == hsa::command_t::ENABLE);
static_assert(static_cast<std::int8_t>(MsgCommandKind::disable) == hsa::command_t::DISABLE);
static_assert(static_cast<std::int8_t>(MsgCommandKind::reset) == hsa::command_t::RESET);
static_assert(static_cast<std::int8_t>(MsgCommandKind::mode) == hsa::command_t::MODE);
static_assert(static_cast<std::int8_t>(MsgCommandKind::gains) == hsa::command_t::GAINS);
static_assert(static_cast<std::int8_t>(MsgCommandKind::move_to) == hsa::command_t::MOVE_TO);
static_assert(static_cast<std::int8_t>(MsgControlMode::position) == hsa::command_t::MODE_POSITION);
static_assert(static_cast<std::int8_t>(MsgControlMode::valve_opening) == hsa::command_t::MODE_VALVE_OPENING);

std::string_view to_string(RejectReason reason) {
  switch (reason) {
    case RejectReason::none: return "none";
#define HSA_REJECT_NAME(reason) \
  case RejectReason::reason: return #reason;
    HSA_REJECT_REASONS(HSA_REJECT_NAME)
#undef HSA_REJECT_NAME
  }
  return "invalid";
}

bool AxisLimits::valid() const {
  return std::isfinite(min_position_m) && std::isfinite(max_position_m) && min_position_m < max_position_m &&
         !std::isnan(max_velocity_m_s) && max_velocity_m_s > 0.0;
}

namespace {

template <typename T>
Validated<T> reject(RejectReason reason) {
  return Validated<T>{reason, T{}};
}

}  // namespace

Validated<SetpointMsg> validate_setpoint(const hsa::setpoint_t& in, const AxisLimits& limits) {
  if (!std::isfinite(in.position_m)) return reject<SetpointMsg>(RejectReason::non_finite);
  if (in.has_velocity_ff && !std::isfinite(in.velocity_ff_m_s)) return reject<SetpointMsg>(RejectReason::non_finite);
  if (in.position_m < limits.min_position_m || in.position_m > limits.max_position_m) {
    return reject<SetpointMsg>(RejectReason::out_of_range);
  }
  if (in.has_velocity_ff && std::fabs(in.velocity_ff_m_s) > limits.max_velocity_m_s) {
    return reject<SetpointMsg>(RejectReason::out_of_range);
  }
  SetpointMsg out;
  out.utime = in.utime;
  out.seq = in.seq;
  out.position_m = in.position_m;
  out.has_velocity_ff = in.has_velocity_ff;
  out.velocity_ff_m_s = in.has_velocity_ff ? in.velocity_ff_m_s : 0.0;
  return {RejectReason::none, out};
}

Validated<CommandMsg> validate_command(const hsa::command_t& in) {
  CommandMsg out;
  out.utime = in.utime;
  out.seq = in.seq;
  switch (in.command) {
    case hsa::command_t::ENABLE: out.kind = MsgCommandKind::enable; break;
    case hsa::command_t::DISABLE: out.kind = MsgCommandKind::disable; break;
    case hsa::command_t::RESET: out.kind = MsgCommandKind::reset; break;
    case hsa::command_t::MODE:
      out.kind = MsgCommandKind::mode;
      if (in.mode == hsa::command_t::MODE_POSITION) {
        out.mode = MsgControlMode::position;
      } else if (in.mode == hsa::command_t::MODE_VALVE_OPENING) {
        out.mode = MsgControlMode::valve_opening;
        if (!std::isfinite(in.valve_opening)) return reject<CommandMsg>(RejectReason::non_finite);
        if (std::fabs(in.valve_opening) > 1.0) return reject<CommandMsg>(RejectReason::out_of_range);
        out.valve_opening = in.valve_opening;
      } else {
        return reject<CommandMsg>(RejectReason::unknown);
      }
      break;
    case hsa::command_t::GAINS:
      out.kind = MsgCommandKind::gains;
      if (!std::isfinite(in.kp) || !std::isfinite(in.ki)) return reject<CommandMsg>(RejectReason::non_finite);
      // The PI needs kp > 0 (control/loop_analysis.hpp); ki = 0 is P control.
      if (!(in.kp > 0.0) || in.ki < 0.0) return reject<CommandMsg>(RejectReason::out_of_range);
      out.kp = in.kp;
      out.ki = in.ki;
      break;
    case hsa::command_t::MOVE_TO:
      out.kind = MsgCommandKind::move_to;
      if (!std::isfinite(in.target_m) || !std::isfinite(in.speed_m_s) || !std::isfinite(in.accel_m_s2)) {
        return reject<CommandMsg>(RejectReason::non_finite);
      }
      // The axis judges the target against its soft limits and the speed against its bound, and
      // answers in status with the reason; a negative speed or acceleration means nothing anywhere.
      if (in.speed_m_s < 0.0 || in.accel_m_s2 < 0.0) return reject<CommandMsg>(RejectReason::out_of_range);
      out.target_m = in.target_m;
      out.speed_m_s = in.speed_m_s;
      out.accel_m_s2 = in.accel_m_s2;
      break;
    default: return reject<CommandMsg>(RejectReason::unknown);
  }
  return {RejectReason::none, out};
}

}  // namespace hsa::daemon
