#include "daemon/supervisor/fault.hpp"

#include <cstdio>

namespace hsa::daemon {

std::string_view to_string(FaultReason reason) noexcept {
  switch (reason) {
    case FaultReason::none: return "none";
    case FaultReason::estop: return "estop";
    case FaultReason::driver_error: return "driver_error";
    case FaultReason::control_output: return "control_output";
    case FaultReason::blind_time: return "blind_time";
    case FaultReason::rt_overruns: return "rt_overruns";
    case FaultReason::sensor_not_ok: return "sensor_not_ok";
    case FaultReason::encoder_stale: return "encoder_stale";
    case FaultReason::encoder_jump: return "encoder_jump";
    case FaultReason::over_pressure: return "over_pressure";
    case FaultReason::soft_limit: return "soft_limit";
    case FaultReason::following_error: return "following_error";
    case FaultReason::current_saturated: return "current_saturated";
    case FaultReason::inputs_not_ready: return "inputs_not_ready";
  }
  return "?";
}

std::string_view summary(FaultReason reason) noexcept {
  switch (reason) {
    case FaultReason::none: return "no fault";
    case FaultReason::estop: return "e-stop";
    case FaultReason::driver_error: return "driver error";
    case FaultReason::control_output: return "control output not finite";
    case FaultReason::blind_time: return "blind time";
    case FaultReason::rt_overruns: return "streak of RT overruns";
    case FaultReason::sensor_not_ok: return "sensor sample not ok";
    case FaultReason::encoder_stale: return "encoder stale";
    case FaultReason::encoder_jump: return "encoder jump";
    case FaultReason::over_pressure: return "pressure over its limit";
    case FaultReason::soft_limit: return "position outside its soft limits";
    case FaultReason::following_error: return "following error over its limit";
    case FaultReason::current_saturated: return "valve command saturated for too long";
    case FaultReason::inputs_not_ready: return "an input gave no first sample at start-up";
  }
  return "?";
}

std::string_view to_string(FaultSignal signal) noexcept {
  switch (signal) {
    case FaultSignal::none: return "";
    case FaultSignal::position: return "position";
    case FaultSignal::pressure_a: return "pressure A";
    case FaultSignal::pressure_b: return "pressure B";
    case FaultSignal::spool: return "spool position";
    case FaultSignal::estop: return "e-stop";
  }
  return "?";
}

std::string describe(const FaultRecord& r) {
  char text[160];
  const std::string signal(to_string(r.signal));
  switch (r.reason) {
    case FaultReason::none:
    case FaultReason::driver_error:
      return std::string(summary(r.reason));
    case FaultReason::estop:
      if (r.status != io::SampleStatus::ok) {
        std::snprintf(text, sizeof text, "e-stop input %s",
                      std::string(io::to_string(r.status)).c_str());
        return text;
      }
      return "e-stop pressed";
    case FaultReason::rt_overruns:
      std::snprintf(text, sizeof text, "%.0f consecutive RT overruns (limit %.0f)", r.value,
                    r.limit);
      return text;
    case FaultReason::control_output:
      std::snprintf(text, sizeof text, "control output not finite (%g): valve set safe", r.value);
      return text;
    case FaultReason::blind_time:
      std::snprintf(text, sizeof text, "blind time: %.1f ms without a cycle (limit %.1f ms)",
                    r.value * 1e3, r.limit * 1e3);
      return text;
    case FaultReason::sensor_not_ok:
      if (r.status == io::SampleStatus::stale && r.limit > 0.0) {
        std::snprintf(text, sizeof text, "%s stale: no new sample for %.1f ms (limit %.1f ms)",
                      signal.c_str(), r.value * 1e3, r.limit * 1e3);
        return text;
      }
      std::snprintf(text, sizeof text, "%s sample %s", signal.c_str(),
                    std::string(io::to_string(r.status)).c_str());
      return text;
    case FaultReason::encoder_stale:
      std::snprintf(text, sizeof text, "encoder stale: no new sample for %.0f cycles (limit %.0f)",
                    r.value, r.limit);
      return text;
    case FaultReason::encoder_jump:
      std::snprintf(text, sizeof text, "encoder jumped %.2f mm between two samples (limit %.2f mm)",
                    r.value * 1e3, r.limit * 1e3);
      return text;
    case FaultReason::over_pressure:
      std::snprintf(text, sizeof text, "%s %.1f bar over limit %.1f bar", signal.c_str(),
                    r.value / 1e5, r.limit / 1e5);
      return text;
    case FaultReason::soft_limit:
      std::snprintf(text, sizeof text, "position %.2f mm beyond soft limit %.2f mm", r.value * 1e3,
                    r.limit * 1e3);
      return text;
    case FaultReason::following_error:
      std::snprintf(text, sizeof text, "following error %.2f mm over limit %.2f mm",
                    r.value * 1e3, r.limit * 1e3);
      return text;
    case FaultReason::current_saturated:
      std::snprintf(text, sizeof text, "valve command saturated for %.0f cycles (limit %.0f)",
                    r.value, r.limit);
      return text;
    case FaultReason::inputs_not_ready:
      std::snprintf(text, sizeof text, "no first sample from %s within %.1f s of start-up (it is %s)",
                    signal.c_str(), r.limit, std::string(io::to_string(r.status)).c_str());
      return text;
  }
  return std::string(summary(r.reason));
}

}  // namespace hsa::daemon
