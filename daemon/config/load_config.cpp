#include "daemon/config/load_config.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "control/law_registry.hpp"
#include "daemon/config/capability_check.hpp"
#include "daemon/config/law_settings_reader.hpp"
#include "daemon/config/metrics_config_reader.hpp"
#include "daemon/config/recorder_config_reader.hpp"
#include "daemon/config/config_bounds.hpp"
#include "daemon/config/input_bounds.hpp"
#include "daemon/config/signal_config_reader.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

namespace {

constexpr std::int64_t kMaxInt = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMicrosecondsPerSecond = 1'000'000;

// Names that end up in LCM channel names (axes) or in messages and references (drivers): kept to
// characters that need no quoting anywhere.
bool is_identifier(std::string_view name, bool allow_dash) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || (allow_dash && c == '-');
    if (!ok) return false;
  }
  return true;
}

// The LCM URL: UDP multicast on a multicast group, with a TTL of 0 (this host) or 1 (the local
// network segment), unless allow_routed_lcm = true. hsad obeys whatever arrives on its channels, so
// a routed TTL, a unicast address or another provider (a file, memq) is a decision to write down,
// not a default to drift into.
std::string parse_lcm_url(const io::TableReader& root) {
  constexpr std::string_view expected = "an LCM URL such as \"udpm://239.255.76.67:7667?ttl=0\"";
  const std::string url = root.string("lcm_url", expected, kDefaultLcmUrl);
  const auto scheme_end = url.find("://");
  if (scheme_end == std::string::npos || scheme_end == 0) root.fail("lcm_url", expected);
  if (root.boolean("allow_routed_lcm", false)) return url;
  constexpr std::string_view local =
      "a udpm:// URL on a multicast group (224.0.0.0/4) with ttl=0 or ttl=1 (or allow_routed_lcm = true)";
  if (url.substr(0, scheme_end) != "udpm") root.fail("lcm_url", local);
  const std::string rest = url.substr(scheme_end + 3);
  const std::string address = rest.substr(0, rest.find_first_of(":?"));
  unsigned a = 0, b = 0, c = 0, d = 0;
  char tail = 0;
  if (std::sscanf(address.c_str(), "%u.%u.%u.%u%c", &a, &b, &c, &d, &tail) != 4 || a < 224 || a > 239 || b > 255 ||
      c > 255 || d > 255) {
    root.fail("lcm_url", local);
  }
  const auto query = rest.find('?');
  std::string ttl = "0";  // LCM's default
  if (query != std::string::npos) {
    std::stringstream options(rest.substr(query + 1));
    for (std::string option; std::getline(options, option, '&');) {
      if (option.rfind("ttl=", 0) == 0) ttl = option.substr(4);
    }
  }
  if (ttl != "0" && ttl != "1") root.fail("lcm_url", local);
  return url;
}

constexpr std::string_view kSystemNameExpected =
    "a system name of 1 to 64 letters, digits, '.', '_' and '-' (default: the host name)";

// A system name travels in every command and status, and is shown to operators.
bool valid_system_name(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

// The default system name: this host's name, so that two rigs on two hosts differ without a line
// of configuration. A host name that is no valid system name is refused: the file must set one.
std::string host_system_name(const io::TableReader& root) {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0 || !valid_system_name(host)) {
    root.fail_here("[auth] system_name is not set, and the host name '" + std::string(host) +
                   "' cannot stand in for it: set [auth] system_name to " + std::string(kSystemNameExpected));
  }
  return host;
}

// Authentication is on unless the file says otherwise: a daemon that obeys anyone must be a
// decision in writing. The keys themselves are read when hsad starts (they are not configuration).
AuthSettings parse_auth(const io::TableReader& t) {
  t.reject_unknown_keys({"require_auth", "key_dir", "stamp_window_s", "lease_timeout_s", "system_name"});
  AuthSettings a;
  if (t.has("system_name")) {
    a.system_name = t.string("system_name", kSystemNameExpected);
    if (!valid_system_name(a.system_name)) t.fail("system_name", kSystemNameExpected);
  }
  a.require_auth = t.boolean("require_auth", a.require_auth);
  a.key_dir = t.string("key_dir", "a folder of <operator>.key files", a.key_dir);
  if (a.key_dir.empty()) t.fail("key_dir", "a folder of <operator>.key files");
  a.stamp_window_s = t.number("stamp_window_s", {.min = 0.0, .max = 60.0, .min_exclusive = true}, a.stamp_window_s);
  a.lease_timeout_s = t.number("lease_timeout_s", {.min = 0.0, .max = 3600.0, .min_exclusive = true}, a.lease_timeout_s);
  return a;
}

RealtimeConfig parse_realtime(const io::TableReader& t) {
  t.reject_unknown_keys(
      {"priority", "cpu", "isolate_cpu", "require_realtime", "base_period_us", "stack_prefault_kib"});
  RealtimeConfig c;
  c.priority = static_cast<int>(t.integer("priority", 1, 99, c.priority));
  c.cpu = static_cast<int>(t.integer("cpu", -1, 1023, c.cpu));  // CPU_SETSIZE is 1024
  c.isolate_cpu = t.boolean("isolate_cpu", c.isolate_cpu);
  c.require_realtime = t.boolean("require_realtime", c.require_realtime);
  c.base_period_us =
      static_cast<std::uint32_t>(t.integer("base_period_us", 10, 100'000, c.base_period_us));
  c.stack_prefault_kib =
      static_cast<std::uint32_t>(t.integer("stack_prefault_kib", 0, 65'536, c.stack_prefault_kib));
  return c;
}

std::vector<DriverConfig> parse_drivers(const io::TableReader& root) {
  if (!root.has("drivers")) root.fail("drivers", "at least one [[drivers]] table");
  std::vector<DriverConfig> drivers;
  for (const io::TableReader& t : root.tables("drivers")) {
    t.reject_unknown_keys({"name", "plugin", "settings"});
    if (drivers.size() == kMaxDriverInstances) {
      t.fail_here("one [[drivers]] table too many: hsad runs at most " + std::to_string(kMaxDriverInstances) +
                  " driver instances (the RT cycle keeps one bit per instance in a 64-bit failure mask); "
                  "one instance of a bus driver can carry the signals of several axes");
    }
    DriverConfig d;
    constexpr std::string_view name_expected = "a driver name of letters, digits, '_' and '-'";
    d.name = t.string("name", name_expected);
    if (!is_identifier(d.name, true)) t.fail("name", name_expected);
    for (std::size_t i = 0; i < drivers.size(); ++i) {
      if (drivers[i].name == d.name) {
        t.fail("name", "a name no other driver has (drivers[" + std::to_string(i) +
                           "] is already called \"" + d.name + "\")");
      }
    }
    // A bare name, looked up in the plugin directories only: a path would let the configuration
    // load any shared library into the real-time process.
    constexpr std::string_view plugin_expected =
        "a plugin name of letters, digits, '_' and '-' such as \"sim\" (no path: plugins are found in "
        "the plugin directories)";
    d.plugin = t.string("plugin", plugin_expected);
    if (!is_identifier(d.plugin, true)) t.fail("plugin", plugin_expected);
    (void)t.table("settings", false, "a table of the plugin's settings");  // taken by take_plugin_settings
    drivers.push_back(std::move(d));
  }
  if (drivers.empty()) root.fail("drivers", "at least one [[drivers]] table");
  return drivers;
}

// Moves each driver's settings table out of the document into its DriverConfig. Moved, not
// copied: a copy of a toml++ node forgets where it was read, and the plugin that reads the table
// names the file, line and column of what it refuses.
void take_plugin_settings(toml::table& document, std::vector<DriverConfig>& drivers) {
  toml::array& tables = *document["drivers"].as_array();
  for (std::size_t i = 0; i < drivers.size(); ++i) {
    if (toml::table* settings = tables[i].as_table()->get_as<toml::table>("settings")) {
      drivers[i].settings = std::move(*settings);
    }
  }
}

// ---- loops -----------------------------------------------------------------------------------

// Base ticks per period of `rate_hz`, or a failure when the rate does not divide the base rate.
std::uint32_t ticks_per(const io::TableReader& t, std::string_view key, std::int64_t rate_hz,
                        const RealtimeConfig& rt) {
  const std::int64_t per_tick = rate_hz * rt.base_period_us;  // µs·Hz: 1e6 when ticks = 1
  if (per_tick > kMicrosecondsPerSecond || kMicrosecondsPerSecond % per_tick != 0) {
    t.fail(key, "a rate in Hz that divides the base rate of " + io::format_setting(rt.base_rate_hz()) +
                    " Hz (realtime.base_period_us = " + std::to_string(rt.base_period_us) +
                    ") exactly");
  }
  return static_cast<std::uint32_t>(kMicrosecondsPerSecond / per_tick);
}

SoftLimits parse_limits(const io::TableReader& t) {
  t.reject_unknown_keys({"soft_min_m", "soft_max_m", "max_accel_m_s2", "max_jerk_m_s3"});
  SoftLimits l;
  l.min_m = t.number("soft_min_m", io::NumberRange::any());
  l.max_m = t.number("soft_max_m", io::NumberRange::above(l.min_m));
  // A lab-scale rod: 100 m/s² is 10 g, 1e4 m/s³ reaches it in 10 ms.
  l.max_accel_m_s2 = t.number("max_accel_m_s2", io::NumberRange::positive(100.0), 0.0);
  l.max_jerk_m_s3 = t.number("max_jerk_m_s3", io::NumberRange::positive(1e4), 0.0);
  return l;
}

SafetyConfig parse_safety(const io::TableReader& t, const control::ControlLaw& law) {
  if (t.has("encoder_stale_cycles")) {
    t.fail("encoder_stale_cycles",
           "encoder_stale_s instead: thresholds that are times are given in seconds (10 base ticks "
           "of 100 us are encoder_stale_s = 0.001)");
  }
  t.reject_unknown_keys({"max_pressure_pa", "max_following_error_m", "following_error_s", "encoder_jump_m",
                         "encoder_stale_s", "current_saturation_s", "overrun_streak",
                         "setpoint_timeout_s", "safe_valve_command", "safe_command_band", "input_stale_s",
                         "max_blind_time_s", "startup_timeout_s"});
  SafetyConfig s;
  const io::NumberRange distance{.min = 0.0, .max = bounds::kMaxDistanceM, .min_exclusive = true};
  const io::NumberRange timeout{.min = 0.0, .max = bounds::kMaxTimeoutS, .min_exclusive = true};
  s.max_pressure_pa = t.number("max_pressure_pa", {.min = 0.0, .max = bounds::kMaxPressurePa, .min_exclusive = true});
  s.max_following_error_m = t.number("max_following_error_m", distance);
  s.encoder_jump_m = t.number("encoder_jump_m", distance);
  s.following_error_s = t.number("following_error_s", timeout, s.following_error_s);
  s.encoder_stale_s = t.number("encoder_stale_s", timeout, s.encoder_stale_s);
  s.current_saturation_s = t.number("current_saturation_s", timeout, s.current_saturation_s);
  s.overrun_streak =
      static_cast<std::uint32_t>(t.integer("overrun_streak", 1, 1'000'000, s.overrun_streak));
  s.setpoint_timeout_s = t.number("setpoint_timeout_s", timeout, s.setpoint_timeout_s);
  s.startup_timeout_s = t.number("startup_timeout_s", timeout, s.startup_timeout_s);
  // Bounded above so that they stay meaningful (and fit the supervisor's ns counters).
  s.input_stale_s = t.number("input_stale_s", timeout, s.input_stale_s);
  s.max_blind_time_s = t.number("max_blind_time_s", {.min = 0.0, .max = 1.0, .min_exclusive = true},
                                s.max_blind_time_s);
  // The safe command must close the valve (config_bounds.hpp): within the band around closed.
  const double band = t.number("safe_command_band", io::NumberRange::closed(0.0, bounds::kMaxSafeCommandBand),
                               bounds::kDefaultSafeCommandBand);
  // The law knows what closes its valve (an opening of 0; a proportional valve's null current or
  // 0 A): the safe command must, within the band.
  s.safe_valve_command = t.number("safe_valve_command", io::NumberRange::any(), law.null_command());
  const std::string refusal = law.safe_command_refusal(s.safe_valve_command, band);
  if (!refusal.empty()) t.fail("safe_valve_command", refusal);
  return s;
}

// Soft limits inside the range the position sensor can report: a limit beyond it could never
// be reached by a reading, so it would never trip.
void check_limits_within_sensor(const io::TableReader& limits, const SoftLimits& l, const AnalogInputConfig& position) {
  const double low = position.params.low_limit;
  const double high = position.params.high_limit;
  const std::string range = "[" + io::format_setting(low) + ", " + io::format_setting(high) + "] m";
  if (std::isfinite(low) && l.min_m < low) {
    limits.fail("soft_min_m", "a limit inside the position sensor's range " + range + " (signals.position)");
  }
  if (std::isfinite(high) && l.max_m > high) {
    limits.fail("soft_max_m", "a limit inside the position sensor's range " + range + " (signals.position)");
  }
}

// The axis-level keys every axis has; a law adds the tables it reads (control/law_registry.hpp).
constexpr std::string_view kAxisKeys[] = {"name", "drive", "cylinder_rate_hz", "telemetry_rate_hz", "area_ratio",
                                          "signals", "limits", "safety", "recorder"};

// The law named by `drive`, read from its tables. A table another law reads is refused by name,
// so a table left over from a change of drive does not pass silently.
std::shared_ptr<const control::ControlLaw> parse_law(const io::TableReader& t, const control::LawTiming& timing,
                                                     std::optional<LoadedPlantSet>& plants) {
  std::vector<std::string_view> known(std::begin(kAxisKeys), std::end(kAxisKeys));
  std::string names;
  for (const control::LawRegistration& law : control::registered_laws()) {
    names += (names.empty() ? "\"" : "\" or \"") + std::string(law.name);
    for (const std::string_view table : law.tables) {
      if (std::find(known.begin(), known.end(), table) == known.end()) known.push_back(table);
    }
  }
  names += '"';
  t.reject_unknown_keys(known);
  const std::string name = t.string("drive", names);
  const control::LawRegistration* law = control::find_law(name);
  if (law == nullptr) t.fail("drive", names);
  for (const control::LawRegistration& other : control::registered_laws()) {
    for (const std::string_view table : other.tables) {
      const bool own = std::find(law->tables.begin(), law->tables.end(), table) != law->tables.end();
      if (!own && t.has(table)) {
        t.fail(table, "no " + std::string(table) + " table with drive = \"" + name + "\" (drive = \"" +
                          std::string(other.name) + "\" reads it)");
      }
    }
  }
  try {
    const LawSettingsReader settings(t);
    std::shared_ptr<const control::ControlLaw> built = law->from_settings(settings, timing);
    plants = settings.loaded_plant_set();
    return built;
  } catch (const std::invalid_argument& e) {
    // Whatever control/ still refuses as a whole is a configuration error too, found now rather
    // than at start-up.
    t.fail_here(std::string("control parameters refused: ") + e.what());
  }
}

AxisConfig parse_axis(const io::TableReader& t, const RealtimeConfig& rt,
                      const std::vector<DriverConfig>& drivers) {
  AxisConfig a;
  constexpr std::string_view name_expected = "an axis name of letters, digits and '_'";
  a.name = t.string("name", name_expected);
  if (!is_identifier(a.name, false)) t.fail("name", name_expected);

  a.cylinder_rate_hz =
      static_cast<std::uint32_t>(t.integer("cylinder_rate_hz", 1, 1'000'000, a.cylinder_rate_hz));
  a.ticks_per_cylinder_tick = ticks_per(t, "cylinder_rate_hz", a.cylinder_rate_hz, rt);
  a.telemetry_rate_hz =
      static_cast<std::uint32_t>(t.integer("telemetry_rate_hz", 1, 1'000'000, a.telemetry_rate_hz));
  a.ticks_per_telemetry = ticks_per(t, "telemetry_rate_hz", a.telemetry_rate_hz, rt);
  a.area_ratio = t.number("area_ratio", io::NumberRange{0.0, 1.0, true, false}, a.area_ratio);

  std::optional<LoadedPlantSet> plants;
  a.law = parse_law(t, {.base_period_s = rt.base_period_s(), .ticks_per_cylinder_tick = a.ticks_per_cylinder_tick},
                    plants);
  a.signals = parse_signals(*t.table("signals", true, "a table of the axis's signals"), *a.law, drivers);
  const io::TableReader limits = *t.table("limits", true, "a table [" + t.key_path("limits") + "]");
  a.limits = parse_limits(limits);
  check_limits_within_sensor(limits, a.limits, a.signals.position);
  if (plants) apply_capability(t, *plants, a);
  a.safety = parse_safety(*t.table("safety", true, "a table [" + t.key_path("safety") + "]"), *a.law);
  a.recorder = parse_axis_recorder(t, rt);
  return a;
}

// Two signals writing one output channel would fight each other every cycle.
void check_outputs_unique(const std::vector<io::TableReader>& axis_tables,
                          const std::vector<AxisConfig>& axes) {
  struct Output {
    std::string driver, channel, owner;
  };
  std::vector<Output> seen;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const io::TableReader signals = *axis_tables[i].table("signals", true, "");
    const auto claim = [&](std::string_view name, const std::string& driver,
                           const std::string& channel) {
      for (const Output& o : seen) {
        if (o.driver == driver && o.channel == channel) {
          signals.table(name, true, "")->fail(
              "channel", "a channel no other output uses (" + o.owner + " already drives '" +
                             channel + "' of driver '" + driver + "')");
        }
      }
      seen.push_back({driver, channel, signals.key_path(name)});
    };
    claim("valve_command", axes[i].signals.valve_command.driver, axes[i].signals.valve_command.channel);
    claim("valve_enable", axes[i].signals.valve_enable.driver, axes[i].signals.valve_enable.channel);
  }
}

std::vector<AxisConfig> parse_axes(const io::TableReader& root, const RealtimeConfig& rt,
                                   const std::vector<DriverConfig>& drivers) {
  constexpr std::string_view expected = "at least one [[axes]] table";
  if (!root.has("axes")) root.fail("axes", expected);
  const std::vector<io::TableReader> tables = root.tables("axes");
  if (tables.empty()) root.fail("axes", expected);
  std::vector<AxisConfig> axes;
  for (const io::TableReader& t : tables) {
    AxisConfig axis = parse_axis(t, rt, drivers);
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (axes[i].name == axis.name) {
        t.fail("name", "a name no other axis has (axes[" + std::to_string(i) +
                           "] is already called \"" + axis.name + "\")");
      }
    }
    axes.push_back(std::move(axis));
  }
  check_outputs_unique(tables, axes);
  return axes;
}

}  // namespace

DaemonConfig parse_config(std::string_view text, std::string_view source_name) {
  check_input_bounds(text, source_name);
  toml::table document = io::parse_toml(text, source_name);
  const io::TableReader root = io::TableReader::root(document, source_name);
  root.reject_unknown_keys({"lcm_url", "allow_routed_lcm", "auth", "realtime", "drivers", "axes", "recorder", "metrics"});

  DaemonConfig c;
  c.source = std::string(source_name);
  c.text = std::string(text);
  c.lcm_url = parse_lcm_url(root);
  if (const auto auth = root.table("auth", false, "a table [auth]")) c.auth = parse_auth(*auth);
  if (c.auth.system_name.empty()) c.auth.system_name = host_system_name(root);
  if (const auto rt = root.table("realtime", false, "a table [realtime]")) c.realtime = parse_realtime(*rt);
  c.drivers = parse_drivers(root);
  c.axes = parse_axes(root, c.realtime, c.drivers);
  c.recorder = parse_recorder(root);
  c.metrics = parse_metrics(root);
  take_plugin_settings(document, c.drivers);
  return c;
}

DaemonConfig load_config(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw io::ConfigError(file.string() + ": cannot open the configuration: " + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    throw io::ConfigError(file.string() + ": cannot read the configuration: " + std::strerror(errno));
  }
  return parse_config(text.str(), file.string());
}

}  // namespace hsa::daemon
