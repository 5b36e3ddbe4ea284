#include "daemon/hsad/axis_setup.hpp"

#include <cmath>
#include <optional>

namespace hsa::daemon {
namespace {

template <class P>
Binding<P> binding(const SignalConfig<P>& s) {
  return Binding<P>{s.driver, s.channel, s.params};
}

template <class P>
std::optional<Binding<P>> binding(const std::optional<SignalConfig<P>>& s) {
  if (!s) return std::nullopt;
  return binding(*s);
}

}  // namespace

AxisParams axis_params(const AxisConfig& a, const RealtimeConfig& rt) {
  AxisParams p;
  p.name = a.name;
  const AxisSignalConfig& s = a.signals;
#define HSA_BIND_INPUT(signal, name, kind, presence, unreadable) p.bindings.signal = binding(s.signal);
  HSA_AXIS_INPUTS(HSA_BIND_INPUT)
#undef HSA_BIND_INPUT
  p.bindings.valve_command = binding(s.valve_command);
  p.bindings.valve_enable = binding(s.valve_enable);

  const double base = rt.base_period_s();
  SupervisorParams& sp = p.safety;
  sp.soft_limit_low_m = a.limits.min_m;
  sp.soft_limit_high_m = a.limits.max_m;
  sp.pressure_max_pa = a.safety.max_pressure_pa;
  sp.following_error_max_m = a.safety.max_following_error_m;
  sp.encoder_jump_max_m = a.safety.encoder_jump_m;
  sp.max_speed_m_s = a.law->max_speed_m_s();
  if (a.limits.max_accel_m_s2 > 0.0) sp.max_accel_m_s2 = a.limits.max_accel_m_s2;
  if (a.limits.max_jerk_m_s3 > 0.0) sp.max_jerk_m_s3 = a.limits.max_jerk_m_s3;
  sp.capability = a.capability;
  sp.following_error_cycles = safety_defaults::ticks_in(a.safety.following_error_s, base);
  sp.encoder_stale_cycles = safety_defaults::ticks_in(a.safety.encoder_stale_s, base);
  sp.input_stale_ns = static_cast<std::int64_t>(a.safety.input_stale_s * 1e9);
  sp.max_blind_time_ns = static_cast<std::int64_t>(a.safety.max_blind_time_s * 1e9);
  sp.saturation_cycles = safety_defaults::ticks_in(a.safety.current_saturation_s, base);
  sp.overrun_streak_max = a.safety.overrun_streak;
  sp.setpoint_timeout_ns = static_cast<std::int64_t>(a.safety.setpoint_timeout_s * 1e9);
  sp.startup_timeout_ns = static_cast<std::int64_t>(a.safety.startup_timeout_s * 1e9);
  p.safe_command = a.safety.safe_valve_command;
  p.law = a.law;
  p.area_ratio = a.area_ratio;
  return p;
}

std::vector<std::string> drivers_of(const AxisConfig& a) {
  const AxisSignalConfig& s = a.signals;
  std::vector<std::string> names{s.valve_command.driver, s.valve_enable.driver};
#define HSA_INPUT_DRIVER(signal, name, kind, presence, unreadable) \
  if (const auto* x = present(s.signal)) names.push_back(x->driver);
  HSA_AXIS_INPUTS(HSA_INPUT_DRIVER)
#undef HSA_INPUT_DRIVER
  return names;
}

}  // namespace hsa::daemon
