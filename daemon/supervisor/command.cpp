#include "daemon/supervisor/command.hpp"

namespace hsa::daemon {

std::string_view to_string(CommandKind kind) noexcept {
  switch (kind) {
    case CommandKind::none: return "none";
#define HSA_COMMAND_NAME(kind, name) \
  case CommandKind::kind: return name;
    HSA_COMMAND_KINDS(HSA_COMMAND_NAME)
#undef HSA_COMMAND_NAME
  }
  return "?";
}

std::string_view to_string(Refusal refusal) noexcept {
  switch (refusal) {
    case Refusal::none: return "accepted";
    case Refusal::reset_first: return "axis in FAULT: reset first";
    case Refusal::estop_active: return "axis in ESTOP: release the e-stop and reset first";
    case Refusal::estop_pressed: return "e-stop still asserted";
    case Refusal::cause_present: return "fault cause still present";
    case Refusal::starting: return "axis starting: waiting for the first sample of every input";
    case Refusal::not_enabled: return "axis not ENABLED: enable it first";
    case Refusal::not_position_mode: return "axis in open-loop mode: a move or an excitation needs position mode";
    case Refusal::target_outside_limits: return "target outside the axis's soft limits";
    case Refusal::speed_over_limit: return "speed over the axis's max_speed_m_s";
    case Refusal::excitation_outside_limits:
      return "excitation outside the axis's soft limits (working point ± amplitude)";
    case Refusal::excitation_invalid: return "excitation parameters refused by the sequence generator";
    case Refusal::accel_over_limit: return "acceleration over the axis's max_accel_m_s2";
    case Refusal::speed_over_extend_capability: return "speed over what the plant can follow extending, its speed_limit_m_s";
    case Refusal::speed_over_retract_capability: return "speed over what the plant can follow retracting, its speed_limit_m_s";
    case Refusal::accel_over_extend_capability:
      return "acceleration over what the plant can follow extending, its acceleration_limit_m_s2";
    case Refusal::accel_over_retract_capability:
      return "acceleration over what the plant can follow retracting, its acceleration_limit_m_s2";
    case Refusal::no_recorder: return "the axis has no flight recorder";
  }
  return "?";
}

}  // namespace hsa::daemon
