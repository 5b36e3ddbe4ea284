#include "daemon/config/describe.hpp"

#include <cmath>
#include <sstream>

#include "drivers/table_reader.hpp"

namespace hsa::daemon {

namespace {

std::string range(double low, double high) {
  if (std::isinf(low) && std::isinf(high)) return "";
  return " limits [" + io::format_setting(low) + ", " + io::format_setting(high) + "]";
}

std::string settings(const io::AnalogInputParams& p) { return range(p.low_limit, p.high_limit); }
std::string settings(const io::AnalogOutputParams& p) { return range(p.low_limit, p.high_limit); }
std::string settings(const io::DigitalInputParams& p) { return p.invert ? " inverted" : ""; }
std::string settings(const io::DigitalOutputParams& p) { return p.invert ? " inverted" : ""; }

template <class Signal>
void line(std::ostringstream& out, std::string_view name, const Signal* s) {
  if (s == nullptr) return;
  out << "    " << name << std::string(name.size() < 14 ? 14 - name.size() : 1, ' ') << s->driver
      << '/' << s->channel << settings(s->params) << '\n';
}

}  // namespace

std::string describe(const DaemonConfig& c) {
  std::ostringstream out;
  const RealtimeConfig& rt = c.realtime;
  out << "configuration " << c.source << '\n'
      << "  LCM URL       " << c.lcm_url << '\n'
      << "  operators     "
      << (c.auth.require_auth ? "authenticated: keys in " + c.auth.key_dir + ", stamp window " +
                                    io::format_setting(c.auth.stamp_window_s) + " s"
                              : std::string("NOT authenticated (require_auth = false): anyone who reaches the LCM URL"))
      << ", lease " << io::format_setting(c.auth.lease_timeout_s) << " s\n"
      << "  system        " << c.auth.system_name << " (commands signed for another system are refused)\n"
      << "  real time     SCHED_FIFO priority " << rt.priority << ", "
      << (rt.cpu < 0 ? std::string("no CPU affinity") : "CPU " + std::to_string(rt.cpu)) << ", "
      << (rt.require_realtime ? "required" : "best effort") << '\n'
      << "  base tick     " << rt.base_period_us << " us (" << io::format_setting(rt.base_rate_hz())
      << " Hz), stack prefault " << rt.stack_prefault_kib << " KiB\n";
  if (c.metrics.enabled()) {
    out << "  metrics       " << c.metrics.textfile << " every " << io::format_setting(c.metrics.interval_s) << " s\n";
  }
  for (const DriverConfig& d : c.drivers) {
    out << "  driver        " << d.name << ": plugin \"" << d.plugin << "\"";
    if (!d.settings.empty()) {
      out << ", settings:";
      for (const auto& [key, value] : d.settings) out << ' ' << key.str();
    }
    out << '\n';
  }
  for (const AxisConfig& a : c.axes) {
    out << "  axis          " << a.name << " (LCM HSA/" << a.name << "/...): drive \"" << a.law->name()
        << "\"\n"
        << "    rates         cylinder loop " << a.cylinder_rate_hz << " Hz (every "
        << a.ticks_per_cylinder_tick << " ticks), telemetry " << a.telemetry_rate_hz
        << " Hz (every " << a.ticks_per_telemetry << " ticks)\n";
    const AxisSignalConfig& s = a.signals;
#define HSA_DESCRIBE_INPUT(signal, name, kind, presence, unreadable) line(out, #signal, present(s.signal));
    HSA_AXIS_INPUTS(HSA_DESCRIBE_INPUT)
#undef HSA_DESCRIBE_INPUT
    line(out, "valve_command", &s.valve_command);
    line(out, "valve_enable", &s.valve_enable);
    out << a.law->describe();
    const SafetyConfig& f = a.safety;
    out << "    soft limits   [" << io::format_setting(a.limits.min_m) << ", "
        << io::format_setting(a.limits.max_m) << "] m\n";
    out << "    moves         max acceleration "
        << (a.limits.max_accel_m_s2 > 0.0 ? io::format_setting(a.limits.max_accel_m_s2) + " m/s²"
                                           : "max speed reached in " + io::format_setting(safety_defaults::kDefaultRampS) + " s")
        << ", jerk "
        << (a.limits.max_jerk_m_s3 > 0.0 ? io::format_setting(a.limits.max_jerk_m_s3) + " m/s³"
                                          : "max acceleration reached in " + io::format_setting(safety_defaults::kDefaultJerkRampS) + " s")
        << '\n';
    if (!a.capability_source.empty()) {
      const MotionCapability& p = a.capability;
      out << "    capability    extending " << io::format_setting(p.extend.speed_m_s) << " m/s, "
          << io::format_setting(p.extend.accel_m_s2) << " m/s²; retracting " << io::format_setting(p.retract.speed_m_s)
          << " m/s, " << io::format_setting(p.retract.accel_m_s2) << " m/s² (" << a.capability_source
          << "): a move is bounded by its direction's\n";
    }
    out
        << "    safety        max pressure " << io::format_setting(f.max_pressure_pa)
        << " Pa, max following error " << io::format_setting(f.max_following_error_m)
        << " m for " << io::format_setting(f.following_error_s) << " s\n"
        << "                  encoder jump max speed x dt + " << io::format_setting(f.encoder_jump_m)
        << " m, stale after " << io::format_setting(f.encoder_stale_s) << " s, " << f.overrun_streak
        << " overruns in a row\n"
        << "                  inputs stale after " << io::format_setting(f.input_stale_s)
        << " s, blind time " << io::format_setting(f.max_blind_time_s) << " s\n"
        << "                  saturated for " << io::format_setting(f.current_saturation_s)
        << " s, setpoint timeout " << io::format_setting(f.setpoint_timeout_s) << " s, start-up timeout "
        << io::format_setting(f.startup_timeout_s) << " s, safe command "
        << io::format_setting(f.safe_valve_command) << a.law->command_unit() << '\n';
  }
  return out.str();
}

}  // namespace hsa::daemon
