#include "daemon/lcm_bridge/message_validation.hpp"

#include <cmath>
#include <cstring>

namespace hsa::daemon {

namespace {

template <typename T>
Validated<T> reject(RejectReason reason) {
  return Validated<T>{reason, T{}};
}

}  // namespace

Validated<SetpointInput> validate_setpoint(const hsa::setpoint_t& in, const AxisLimits& limits) {
  if (!std::isfinite(in.position_m)) return reject<SetpointInput>(RejectReason::non_finite);
  if (in.has_velocity_ff && !std::isfinite(in.velocity_ff_m_s)) return reject<SetpointInput>(RejectReason::non_finite);
  if (in.position_m < limits.min_position_m || in.position_m > limits.max_position_m) {
    return reject<SetpointInput>(RejectReason::out_of_range);
  }
  if (in.has_velocity_ff && std::fabs(in.velocity_ff_m_s) > limits.max_velocity_m_s) {
    return reject<SetpointInput>(RejectReason::out_of_range);
  }
  // The sender's seq, for the record: the RT thread numbers the setpoints it takes itself, as two
  // senders may both count from 1.
  SetpointInput out;
  out.seq = static_cast<std::uint64_t>(in.seq);
  out.utime = in.utime;
  out.target = in.position_m;
  out.velocity_m_s = in.has_velocity_ff ? in.velocity_ff_m_s : 0.0;
  return {RejectReason::none, out};
}

// The one place the wire's command constants become the supervisor's vocabulary.
Validated<AxisCommand> validate_command(const hsa::command_t& in) {
  AxisCommand out;
  switch (in.command) {
    case hsa::command_t::ENABLE: out.kind = CommandKind::enable; break;
    case hsa::command_t::DISABLE: out.kind = CommandKind::disable; break;
    case hsa::command_t::RESET: out.kind = CommandKind::reset; break;
    case hsa::command_t::MODE:
      out.kind = CommandKind::set_mode;
      if (in.mode == hsa::command_t::MODE_POSITION) {
        out.mode = ControlMode::position;
      } else if (in.mode == hsa::command_t::MODE_VALVE_OPENING) {
        out.mode = ControlMode::open_loop;
        if (!std::isfinite(in.valve_opening) || !std::isfinite(in.opening_duration_s)) {
          return reject<AxisCommand>(RejectReason::non_finite);
        }
        if (std::fabs(in.valve_opening) > 1.0) return reject<AxisCommand>(RejectReason::out_of_range);
        if (!(in.opening_duration_s >= 0.0 && in.opening_duration_s <= kMaxOpeningDurationS)) {
          return reject<AxisCommand>(RejectReason::out_of_range);
        }
        out.has_opening = true;
        out.opening = in.valve_opening;
        out.opening_duration_s = in.opening_duration_s;
      } else {
        return reject<AxisCommand>(RejectReason::unknown);
      }
      break;
    case hsa::command_t::GAINS:
      out.kind = CommandKind::gains;
      if (!std::isfinite(in.kp) || !std::isfinite(in.ki)) return reject<AxisCommand>(RejectReason::non_finite);
      // The PI needs kp > 0 (control/loop_analysis.hpp); ki = 0 is P control.
      if (!(in.kp > 0.0) || in.ki < 0.0) return reject<AxisCommand>(RejectReason::out_of_range);
      out.gains = {.kp = in.kp, .ki = in.ki};
      break;
    case hsa::command_t::MOVE_TO:
      out.kind = CommandKind::move_to;
      if (!std::isfinite(in.target_m) || !std::isfinite(in.speed_m_s) || !std::isfinite(in.accel_m_s2)) {
        return reject<AxisCommand>(RejectReason::non_finite);
      }
      // The axis judges the target against its soft limits and the speed against its bound, and
      // answers in status with the reason; a negative speed or acceleration means nothing anywhere.
      if (in.speed_m_s < 0.0 || in.accel_m_s2 < 0.0) return reject<AxisCommand>(RejectReason::out_of_range);
      out.move = {.target_m = in.target_m, .speed_m_s = in.speed_m_s, .accel_m_s2 = in.accel_m_s2};
      break;
    case hsa::command_t::EXCITE: {
      out.kind = CommandKind::excite;
      if (!std::isfinite(in.excite_working_point_m) || !std::isfinite(in.excite_amplitude_m) ||
          !std::isfinite(in.excite_switching_s) || !std::isfinite(in.excite_duration_s) ||
          !std::isfinite(in.excite_kp)) {
        return reject<AxisCommand>(RejectReason::non_finite);
      }
      ExcitationRequest& e = out.excite;
      if (in.excite_kind == hsa::command_t::EXCITE_PRMS) {
        e.kind = control::ExcitationKind::prms;
        if (in.excite_levels < 2 || in.excite_levels > kMaxExcitationLevels) {
          return reject<AxisCommand>(RejectReason::out_of_range);
        }
        e.levels = in.excite_levels;
      } else if (in.excite_kind == hsa::command_t::EXCITE_PRBS) {
        e.kind = control::ExcitationKind::prbs;
        e.levels = 2;
      } else {
        return reject<AxisCommand>(RejectReason::unknown);
      }
      // What means nothing anywhere; the axis judges the rest against its limits and answers.
      if (!(in.excite_amplitude_m > 0.0) || !(in.excite_switching_s > 0.0) || !(in.excite_duration_s > 0.0) ||
          in.excite_duration_s > kMaxExcitationDurationS || in.excite_kp < 0.0) {
        return reject<AxisCommand>(RejectReason::out_of_range);
      }
      e.working_point_m = in.excite_working_point_m;
      e.at_rod = in.excite_at_rod;
      e.amplitude_m = in.excite_amplitude_m;
      e.switching_time_s = in.excite_switching_s;
      e.duration_s = in.excite_duration_s;
      e.seed = static_cast<std::uint64_t>(in.excite_seed);
      e.kp_per_m = in.excite_kp > 0.0 ? in.excite_kp : kDefaultExcitationKpPerM;
      break;
    }
    case hsa::command_t::CAPTURE: {
      out.kind = CommandKind::capture;
      CaptureRequest& c = out.capture;
      switch (in.capture_action) {
        case hsa::command_t::CAPTURE_NOW: c.action = CaptureAction::now; break;
        case hsa::command_t::CAPTURE_ARM: c.action = CaptureAction::arm; break;
        case hsa::command_t::CAPTURE_DISARM: c.action = CaptureAction::disarm; return {RejectReason::none, out};
        default: return reject<AxisCommand>(RejectReason::unknown);
      }
      if (!std::isfinite(in.capture_pre_s) || !std::isfinite(in.capture_post_s)) {
        return reject<AxisCommand>(RejectReason::non_finite);
      }
      c.pre_s = in.capture_pre_s;
      c.post_s = in.capture_post_s;
      if (c.action == CaptureAction::arm) {
        if (!std::isfinite(in.capture_level)) return reject<AxisCommand>(RejectReason::non_finite);
        // The name crosses the ring in a fixed array; the operator thread judges it (capture_gate).
        if (in.capture_signal.empty() || in.capture_signal.size() >= kCaptureSignalSize) {
          return reject<AxisCommand>(RejectReason::out_of_range);
        }
        std::memcpy(c.signal, in.capture_signal.data(), in.capture_signal.size());
        c.crossing = in.capture_below ? Crossing::below : Crossing::above;
        c.level = in.capture_level;
        c.repeat = in.capture_repeat;
      }
      break;
    }
    default: return reject<AxisCommand>(RejectReason::unknown);
  }
  return {RejectReason::none, out};
}

}  // namespace hsa::daemon
