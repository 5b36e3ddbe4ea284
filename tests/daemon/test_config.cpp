// The daemon's configuration: every class of error names the file, the line and column, the key
// path and what was expected; the example files in systemd/ parse.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <stdexcept>
#include <string_view>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/cascade.hpp"
#include "control/laws/pi_cascade_law.hpp"
#include "daemon/config/describe.hpp"
#include "daemon/config/load_config.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;

// The smallest valid configuration: every required key and nothing else.
constexpr std::string_view kMinimal = R"([[drivers]]
name = "rig"
plugin = "sim"

[[axes]]
name = "x"
drive = "direct"
[axes.signals.position]
driver = "rig"
channel = "encoder"
[axes.signals.pressure_a]
driver = "rig"
channel = "pressure_a"
[axes.signals.pressure_b]
driver = "rig"
channel = "pressure_b"
[axes.signals.valve_command]
driver = "rig"
channel = "opening_cmd"
[axes.signals.valve_enable]
driver = "rig"
channel = "valve_enable"
[axes.pi]
kp = 85.0
ki = 460.0
max_speed_m_s = 0.2
[axes.limits]
soft_min_m = 0.01
soft_max_m = 0.29
[axes.safety]
max_pressure_pa = 30e5
max_following_error_m = 0.02
encoder_jump_m = 0.005
)";

// The same axis on the proportional valve, in cascade.
constexpr std::string_view kProportional = R"([[drivers]]
name = "rig"
plugin = "sim"
[drivers.settings]
valve = "proportional"

[[axes]]
name = "x"
drive = "proportional"
[axes.signals.position]
driver = "rig"
channel = "encoder"
[axes.signals.pressure_a]
driver = "rig"
channel = "pressure_a"
[axes.signals.pressure_b]
driver = "rig"
channel = "pressure_b"
[axes.signals.spool]
driver = "rig"
channel = "spool_lvdt"
[axes.signals.valve_command]
driver = "rig"
channel = "current_ref"
[axes.signals.valve_enable]
driver = "rig"
channel = "valve_enable"
[axes.pi]
kp = 85.0
ki = 460.0
max_speed_m_s = 0.2
[axes.valve_law]
bias_current_a = 1.5
proportional_a_per_m = 3300.0
[axes.limits]
soft_min_m = 0.01
soft_max_m = 0.29
[axes.safety]
max_pressure_pa = 30e5
max_following_error_m = 0.02
encoder_jump_m = 0.005
)";

// `text` with the first occurrence of `from` replaced by `to`.
std::string replace(std::string_view text, std::string_view from, std::string_view to) {
  std::string out(text);
  const auto at = out.find(from);
  EXPECT_NE(at, std::string::npos) << "no '" << from << "' in the text";
  if (at != std::string::npos) out.replace(at, from.size(), to);
  return out;
}

// 1-based line of the character at `at`.
int line_at(std::string_view text, std::size_t at) {
  EXPECT_LT(at, text.size());
  int line = 1;
  for (std::size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

// 1-based line of the first (or last) occurrence of `needle`.
int line_of(std::string_view text, std::string_view needle) { return line_at(text, text.find(needle)); }
int last_line_of(std::string_view text, std::string_view needle) {
  return line_at(text, text.rfind(needle));
}

// The cascade parameters of an axis's law (both of control/'s PI laws run a control::Cascade).
const control::CascadeParams& cascade_of(const AxisConfig& a) {
  return dynamic_cast<const control::PiCascadeLaw&>(*a.law).cascade().params();
}

// The message of the io::ConfigError that parsing `text` throws (empty when it does not throw).
std::string error_of(std::string_view text) {
  try {
    (void)parse_config(text, "test.toml");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "parsing did not throw";
  return {};
}

// "test.toml:<line>:" — the file and the line, at the start of the message.
std::string at_line(int line) { return "test.toml:" + std::to_string(line) + ":"; }

// Asserts the four parts of a message: file and line, key path, expectation.
void expect_message(const std::string& message, int line, std::string_view key_path,
                    std::string_view expected) {
  EXPECT_THAT(message, ::testing::StartsWith(at_line(line))) << message;
  EXPECT_THAT(message, HasSubstr(": " + std::string(key_path) + ": ")) << message;
  EXPECT_THAT(message, HasSubstr(std::string(expected))) << message;
}

TEST(DaemonConfig, MinimalConfigurationTakesTheDocumentedDefaults) {
  const DaemonConfig c = parse_config(kMinimal, "test.toml");
  EXPECT_EQ(c.source, "test.toml");
  EXPECT_EQ(c.lcm_url, "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_TRUE(c.auth.require_auth);  // on unless the file says otherwise
  EXPECT_EQ(c.auth.key_dir, "/etc/hsa/keys");
  EXPECT_EQ(c.auth.stamp_window_s, 2.0);
  EXPECT_EQ(c.auth.lease_timeout_s, 30.0);
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(c.auth.system_name, host);  // the host name, unless the file names the system
  EXPECT_EQ(c.realtime.priority, 80);
  EXPECT_EQ(c.realtime.cpu, -1);
  EXPECT_FALSE(c.realtime.require_realtime);
  EXPECT_EQ(c.realtime.base_period_us, 100u);
  ASSERT_EQ(c.drivers.size(), 1u);
  EXPECT_EQ(c.drivers[0].name, "rig");
  EXPECT_EQ(c.drivers[0].plugin, "sim");
  EXPECT_TRUE(c.drivers[0].settings.empty());

  ASSERT_EQ(c.axes.size(), 1u);
  const AxisConfig& a = c.axes[0];
  EXPECT_EQ(a.name, "x");
  EXPECT_EQ(a.law->name(), "direct");
  EXPECT_EQ(a.cylinder_rate_hz, 1000u);
  EXPECT_EQ(a.ticks_per_cylinder_tick, 10u);
  EXPECT_EQ(a.telemetry_rate_hz, 1000u);
  EXPECT_EQ(a.ticks_per_telemetry, 10u);
  EXPECT_EQ(a.signals.position.driver, "rig");
  EXPECT_EQ(a.signals.position.channel, "encoder");
  EXPECT_TRUE(std::isinf(a.signals.position.params.high_limit));
  EXPECT_FALSE(a.signals.spool.has_value());
  EXPECT_FALSE(a.signals.estop.has_value());
  EXPECT_EQ(cascade_of(a).drive, control::ValveDrive::direct);
  EXPECT_EQ(cascade_of(a).cylinder.kp, 85.0);
  EXPECT_EQ(cascade_of(a).cylinder.ki, 460.0);
  EXPECT_DOUBLE_EQ(cascade_of(a).cylinder.period_s, 1e-3);
  EXPECT_DOUBLE_EQ(cascade_of(a).valve.period_s, 1e-4);
  EXPECT_EQ(cascade_of(a).cylinder.max_setpoint_rate_m_s, 0.2);
  // Runtime gain bounds default to twice the configured gains.
  EXPECT_EQ(a.law->gain_bounds().max_kp, 2.0 * 85.0);
  EXPECT_EQ(a.law->gain_bounds().max_ki, 2.0 * 460.0);
  // The feed-forward inverts the paper's nominal plant (control/motion_feedforward.hpp).
  EXPECT_EQ(cascade_of(a).cylinder.velocity_feedforward, control::kNominalFeedforward.velocity);
  EXPECT_EQ(cascade_of(a).cylinder.acceleration_feedforward, control::kNominalFeedforward.accel);
  EXPECT_EQ(cascade_of(a).cylinder.jerk_feedforward, control::kNominalFeedforward.jerk);
  EXPECT_EQ(a.limits.max_accel_m_s2, 0.0);  // derived from the speed
  EXPECT_EQ(a.limits.max_jerk_m_s3, 0.0);
  EXPECT_EQ(a.limits.min_m, 0.01);
  EXPECT_EQ(a.limits.max_m, 0.29);
  EXPECT_EQ(a.safety.max_pressure_pa, 30e5);
  EXPECT_EQ(a.safety.encoder_stale_s, 0.001);
  EXPECT_EQ(a.safety.following_error_s, 0.01);
  EXPECT_EQ(a.safety.overrun_streak, 10u);
  EXPECT_EQ(a.safety.max_blind_time_s, 0.005);
  EXPECT_EQ(a.safety.input_stale_s, 0.1);
  EXPECT_EQ(a.safety.setpoint_timeout_s, 0.5);
  EXPECT_EQ(a.safety.safe_valve_command, 0.0);
  EXPECT_NO_THROW(control::Cascade{cascade_of(a)});
}

TEST(DaemonConfig, ReadsBindingParametersAndDriverSettings) {
  std::string text = replace(kMinimal, "plugin = \"sim\"\n",
                             "plugin = \"sim\"\n[drivers.settings]\nvalve = \"servo\"\nseed = 7\n");
  text = replace(text, "channel = \"pressure_a\"\n",
                 "channel = \"pressure_a\"\nlow_limit = 0\nhigh_limit = 4e6\n");
  text = replace(text, "channel = \"valve_enable\"\n",
                 "channel = \"valve_enable\"\ninvert = true\n[axes.signals.estop]\ndriver = \"rig\"\n"
                 "channel = \"estop\"\ninvert = true\n");
  const DaemonConfig c = parse_config(text, "test.toml");
  const toml::table& settings = c.drivers[0].settings;
  EXPECT_EQ(settings["valve"].value<std::string>(), "servo");
  EXPECT_EQ(settings["seed"].value<std::int64_t>(), 7);
  const io::AnalogInputParams& p = c.axes[0].signals.pressure_a.params;
  EXPECT_EQ(p.low_limit, 0.0);
  EXPECT_EQ(p.high_limit, 4e6);
  EXPECT_TRUE(c.axes[0].signals.valve_enable.params.invert);
  ASSERT_TRUE(c.axes[0].signals.estop.has_value());
  EXPECT_TRUE(c.axes[0].signals.estop->params.invert);
}

TEST(DaemonConfig, ProportionalDriveBuildsTheCascade) {
  const DaemonConfig c = parse_config(kProportional, "test.toml");
  const AxisConfig& a = c.axes[0];
  EXPECT_EQ(a.law->name(), "proportional");
  EXPECT_EQ(cascade_of(a).drive, control::ValveDrive::proportional);
  ASSERT_TRUE(a.signals.spool.has_value());
  EXPECT_EQ(a.signals.spool->channel, "spool_lvdt");
  EXPECT_EQ(cascade_of(a).valve.bias_current_a, 1.5);
  EXPECT_EQ(cascade_of(a).valve.proportional_a_per_m, 3300.0);
  EXPECT_EQ(cascade_of(a).valve.max_current_a, 3.0);
  EXPECT_EQ(a.safety.safe_valve_command, 1.5);  // defaults to the bias current
  EXPECT_EQ(cascade_of(a).valve.dither_amplitude_a, 0.0);  // off unless asked for
  EXPECT_NO_THROW(control::Cascade{cascade_of(a)});
}

TEST(DaemonConfig, ValveLawDitherIsReadWithItsFrequency) {
  const DaemonConfig c = parse_config(
      replace(kProportional, "bias_current_a = 1.5", "bias_current_a = 1.5\ndither_amplitude_a = 0.3\ndither_frequency_hz = 500"),
      "test.toml");
  const control::ValveLawParams& v = cascade_of(c.axes[0]).valve;
  EXPECT_EQ(v.dither_amplitude_a, 0.3);
  EXPECT_EQ(v.dither_frequency_hz, 500.0);
  EXPECT_NO_THROW(control::Cascade{cascade_of(c.axes[0])});
}

TEST(DaemonConfig, RatesSetTheLoopPeriods) {
  std::string text = replace(kMinimal, "drive = \"direct\"\n",
                             "drive = \"direct\"\ncylinder_rate_hz = 2000\ntelemetry_rate_hz = 100\n");
  text = "[realtime]\nbase_period_us = 50\n" + text;
  const AxisConfig a = parse_config(text, "test.toml").axes[0];
  EXPECT_EQ(a.ticks_per_cylinder_tick, 10u);
  EXPECT_EQ(a.ticks_per_telemetry, 200u);
  EXPECT_DOUBLE_EQ(cascade_of(a).valve.period_s, 5e-5);
  EXPECT_DOUBLE_EQ(cascade_of(a).cylinder.period_s, 5e-4);
  EXPECT_NO_THROW(control::Cascade{cascade_of(a)});
}

TEST(DaemonConfigErrors, SyntaxErrorNamesFileAndLine) {
  const std::string text = replace(kMinimal, "ki = 460.0", "ki = = 460.0");
  const std::string message = error_of(text);
  EXPECT_THAT(message, ::testing::StartsWith(at_line(line_of(text, "ki = =")))) << message;
  EXPECT_THAT(message, HasSubstr("TOML syntax error")) << message;
}

TEST(DaemonConfigErrors, KeyDefinedTwiceIsASyntaxError) {
  const std::string text = replace(kMinimal, "ki = 460.0", "kp = 1.0");
  const std::string message = error_of(text);
  EXPECT_THAT(message, ::testing::StartsWith(at_line(line_of(text, "kp = 1.0")))) << message;
  EXPECT_THAT(message, HasSubstr("kp")) << message;
}

TEST(DaemonConfigErrors, OutOfRangeNumberGivesTheWholeMessage) {
  const std::string text = replace(kMinimal, "kp = 85.0", "kp = -3");
  const int line = line_of(text, "kp = -3");
  EXPECT_EQ(error_of(text), at_line(line) + "6: axes[0].pi.kp: expected a finite number in (0, 10000], got -3");
}

TEST(DaemonConfig, OptionalPiTermsAreRead) {
  const DaemonConfig c = parse_config(
      replace(kMinimal, "ki = 460.0",
              "ki = 460.0\nvelocity_feedforward = 5.5\nacceleration_feedforward = 0.04\njerk_feedforward = 0\n"
              "integral_dead_band_m = 5e-6"),
      "t.toml");
  EXPECT_EQ(cascade_of(c.axes[0]).cylinder.velocity_feedforward, 5.5);
  EXPECT_EQ(cascade_of(c.axes[0]).cylinder.acceleration_feedforward, 0.04);
  EXPECT_EQ(cascade_of(c.axes[0]).cylinder.jerk_feedforward, 0.0);
  EXPECT_EQ(cascade_of(c.axes[0]).cylinder.integral_dead_band_m, 5e-6);
}

TEST(DaemonConfig, MoveBoundsAreReadAndOutOfRangeOnesNamed) {
  const DaemonConfig c =
      parse_config(replace(kMinimal, "soft_max_m = 0.29", "soft_max_m = 0.29\nmax_accel_m_s2 = 1.5\nmax_jerk_m_s3 = 30"), "t.toml");
  EXPECT_EQ(c.axes[0].limits.max_accel_m_s2, 1.5);
  EXPECT_EQ(c.axes[0].limits.max_jerk_m_s3, 30.0);
  const std::pair<std::string, std::string> keys[] = {{"max_accel_m_s2", "(0, 100]"}, {"max_jerk_m_s3", "(0, 10000]"}};
  for (const auto& [key, range] : keys) {
    for (const std::string value : {"0", "-1", "inf", "20000"}) {
      const std::string text = replace(kMinimal, "soft_max_m = 0.29", "soft_max_m = 0.29\n" + key + " = " + value);
      expect_message(error_of(text), line_of(text, key), "axes[0].limits." + key,
                     "expected a finite number in " + range + ", got " + value);
    }
  }
}

TEST(DaemonConfig, GainBoundsAreRead) {
  const DaemonConfig c = parse_config(replace(kMinimal, "ki = 460.0", "ki = 460.0\nmax_kp = 300\nmax_ki = 460"), "t.toml");
  EXPECT_EQ(c.axes[0].law->gain_bounds().max_kp, 300.0);
  EXPECT_EQ(c.axes[0].law->gain_bounds().max_ki, 460.0);  // equal to ki: the operator may not raise it
  EXPECT_THAT(describe(c), HasSubstr("at run time up to 300 and 460"));
}

// A bound below the configured gain would refuse the configuration's own gains; a bound that is
// not a finite number bounds nothing.
TEST(DaemonConfigErrors, GainBoundsBelowTheGainsOrNotFiniteAreRefused) {
  const struct {
    const char* line;
    const char* key;
    const char* expected;
  } cases[] = {
      {"max_kp = 50", "max_kp", "expected a finite number in [85, 10000], got 50"},
      {"max_kp = inf", "max_kp", "expected a finite number in [85, 10000], got inf"},
      {"max_kp = nan", "max_kp", "expected a finite number in [85, 10000], got nan"},
      {"max_ki = 400", "max_ki", "expected a finite number in [460, 1000000], got 400"},
      {"max_ki = -1", "max_ki", "expected a finite number in [460, 1000000], got -1"},
      {"max_ki = inf", "max_ki", "expected a finite number in [460, 1000000], got inf"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.line);
    const std::string text = replace(kMinimal, "ki = 460.0", std::string("ki = 460.0\n") + c.line);
    expect_message(error_of(text), line_of(text, c.line), std::string("axes[0].pi.") + c.key, c.expected);
  }
}

// The setpoint rate limit is what keeps a client from stepping the rod: it must be there, finite
// and positive.
TEST(DaemonConfigErrors, MaxSpeedIsRequiredFiniteAndPositive) {
  {
    const std::string text = replace(kMinimal, "max_speed_m_s = 0.2\n", "");
    expect_message(error_of(text), line_of(text, "[axes.pi]"), "axes[0].pi.max_speed_m_s",
                   "required key is missing, expected a finite number in (0, 5]");
  }
  {
    const std::string text = replace(kProportional, "max_speed_m_s = 0.2\n", "");
    expect_message(error_of(text), line_of(text, "[axes.pi]"), "axes[0].pi.max_speed_m_s",
                   "required key is missing, expected a finite number in (0, 5]");
  }
  for (const std::string value : {"inf", "nan", "0", "-1", "6"}) {
    SCOPED_TRACE(value);
    const std::string text = replace(kMinimal, "max_speed_m_s = 0.2", "max_speed_m_s = " + value);
    expect_message(error_of(text), line_of(text, "max_speed_m_s"), "axes[0].pi.max_speed_m_s",
                   "expected a finite number in (0, 5], got " + value);
  }
}

TEST(DaemonConfigErrors, NegativeOptionalPiTermsAreRefused) {
  const std::pair<std::string, std::string> keys[] = {{"velocity_feedforward", "[0, 100]"},
                                                      {"acceleration_feedforward", "[0, 1]"},
                                                      {"jerk_feedforward", "[0, 0.01]"},
                                                      {"integral_dead_band_m", "[0, 0.01]"}};
  for (const auto& [key, range] : keys) {
    const std::string text = replace(kMinimal, "ki = 460.0", "ki = 460.0\n" + key + " = -1");
    expect_message(error_of(text), line_of(text, key), "axes[0].pi." + key, "expected a finite number in " + range + ", got -1");
  }
}

TEST(DaemonConfigErrors, WrongType) {
  {
    const std::string text = replace(kMinimal, "kp = 85.0", "kp = \"fast\"");
    expect_message(error_of(text), line_of(text, "kp ="), "axes[0].pi.kp",
                   "expected a finite number in (0, 10000], got \"fast\"");
  }
  {
    const std::string text = "[realtime]\nrequire_realtime = \"yes\"\n" + std::string(kMinimal);
    expect_message(error_of(text), 2, "realtime.require_realtime", "expected true or false, got \"yes\"");
  }
  {
    const std::string text = "[realtime]\npriority = 80.5\n" + std::string(kMinimal);
    expect_message(error_of(text), 2, "realtime.priority", "expected an integer in [1, 99], got 80.5");
  }
  {
    const std::string text = replace(kMinimal, "name = \"x\"", "name = 3");
    expect_message(error_of(text), line_of(text, "name = 3"), "axes[0].name",
                   "expected an axis name of letters, digits and '_', got 3");
  }
  {
    const std::string text = "realtime = 3\n" + std::string(kMinimal);
    expect_message(error_of(text), 1, "realtime", "expected a table [realtime], got 3");
  }
}

TEST(DaemonConfigErrors, OutOfRange) {
  {
    const std::string text = replace(kMinimal, "drive = \"direct\"", "drive = \"direct\"\narea_ratio = 1.5");
    expect_message(error_of(text), line_of(text, "area_ratio = 1.5"), "axes[0].area_ratio", "got 1.5");
  }
  {
    const std::string text = "[realtime]\npriority = 100\n" + std::string(kMinimal);
    expect_message(error_of(text), 2, "realtime.priority", "expected an integer in [1, 99], got 100");
  }
  {
    const std::string text = "[realtime]\ncpu = -2\n" + std::string(kMinimal);
    expect_message(error_of(text), 2, "realtime.cpu", "expected an integer in [-1, 1023], got -2");
  }
  {
    const std::string text = replace(kMinimal, "ki = 460.0", "ki = nan");
    expect_message(error_of(text), line_of(text, "ki = nan"), "axes[0].pi.ki",
                   "expected a finite number in [0, 1000000], got nan");
  }
  {
    const std::string text = replace(kMinimal, "max_pressure_pa = 30e5", "max_pressure_pa = inf");
    expect_message(error_of(text), line_of(text, "max_pressure_pa"), "axes[0].safety.max_pressure_pa",
                   "expected a finite number in (0, 70000000], got inf");
  }
  {
    const std::string text = replace(kMinimal, "soft_max_m = 0.29", "soft_max_m = 0.005");
    expect_message(error_of(text), line_of(text, "soft_max_m"), "axes[0].limits.soft_max_m",
                   "expected a finite number > 0.01, got 0.005");
  }
  {
    const std::string text = replace(kMinimal, "channel = \"encoder\"",
                                     "channel = \"encoder\"\nlow_limit = 0.3\nhigh_limit = 0.1");
    expect_message(error_of(text), line_of(text, "high_limit"), "axes[0].signals.position.high_limit",
                   "expected a finite number > 0.3, got 0.1");
  }
  {
    const std::string text = replace(kProportional, "bias_current_a = 1.5",
                                     "bias_current_a = 1.5\ndither_amplitude_a = 0.3\ndither_frequency_hz = 3000");
    expect_message(error_of(text), line_of(text, "dither_frequency_hz"), "axes[0].valve_law.dither_frequency_hz",
                   "expected a frequency whose half period is a whole number of 0.0001 s base ticks (5000 Hz, "
                   "2500 Hz, 1666.67 Hz, ...), got 3000");
  }
  {
    const std::string text = replace(kProportional, "bias_current_a = 1.5",
                                     "bias_current_a = 1.5\ndither_amplitude_a = 1.6\ndither_frequency_hz = 500");
    expect_message(error_of(text), line_of(text, "dither_amplitude_a"), "axes[0].valve_law.dither_amplitude_a",
                   "expected a finite number in [0, 1.5], got 1.6");
  }
  {
    const std::string text = replace(kProportional, "bias_current_a = 1.5", "bias_current_a = 1.5\ndither_amplitude_a = 0.3");
    expect_message(error_of(text), line_of(text, "[axes.valve_law]"), "axes[0].valve_law.dither_frequency_hz",
                   "required key is missing, expected a finite number > 0");
  }
  {
    const std::string text = replace(kMinimal, "encoder_jump_m = 0.005",
                                     "encoder_jump_m = 0.005\nsafe_valve_command = 1.5");
    expect_message(error_of(text), line_of(text, "safe_valve_command"),
                   "axes[0].safety.safe_valve_command", "expected a finite number in [-0.02, 0.02], got 1.5");
  }
  for (const char* value : {"0.0", "-0.001", "nan", "inf", "2.0"}) {
    SCOPED_TRACE(value);
    const std::string text = replace(kMinimal, "encoder_jump_m = 0.005",
                                     std::string("encoder_jump_m = 0.005\nmax_blind_time_s = ") + value);
    expect_message(error_of(text), line_of(text, "max_blind_time_s"), "axes[0].safety.max_blind_time_s",
                   "expected a finite number in (0, 1], got");
  }
  for (const char* value : {"0.0", "nan", "11.0"}) {
    SCOPED_TRACE(value);
    const std::string text = replace(kMinimal, "encoder_jump_m = 0.005",
                                     std::string("encoder_jump_m = 0.005\ninput_stale_s = ") + value);
    expect_message(error_of(text), line_of(text, "input_stale_s"), "axes[0].safety.input_stale_s",
                   "expected a finite number in (0, 10], got");
  }
  {
    const std::string text = replace(kMinimal, "encoder_jump_m = 0.005",
                                     "encoder_jump_m = 0.005\nmax_blind_time_s = 0.02\ninput_stale_s = 0.25");
    const DaemonConfig c = parse_config(text, "hsad.toml");
    EXPECT_EQ(c.axes[0].safety.max_blind_time_s, 0.02);
    EXPECT_EQ(c.axes[0].safety.input_stale_s, 0.25);
  }
  {
    const std::string text = replace(kProportional, "bias_current_a = 1.5", "bias_current_a = 3.5");
    expect_message(error_of(text), line_of(text, "bias_current_a"), "axes[0].valve_law.bias_current_a",
                   "expected a finite number in [0, 3], got 3.5");
  }
  {
    const std::string text = replace(kMinimal, "name = \"x\"", "name = \"x/y\"");
    expect_message(error_of(text), line_of(text, "name = \"x/y\""), "axes[0].name",
                   "expected an axis name of letters, digits and '_', got \"x/y\"");
  }
  {
    const std::string text = "lcm_url = \"239.255.76.67\"\n" + std::string(kMinimal);
    expect_message(error_of(text), 1, "lcm_url", "expected an LCM URL");
  }
}

TEST(DaemonConfigErrors, UnknownKeyIsAnError) {
  {
    const std::string text = replace(kMinimal, "ki = 460.0", "ki = 460.0\nkpp = 1.0");
    expect_message(error_of(text), line_of(text, "kpp"), "axes[0].pi.kpp",
                   "unknown key, expected one of: kp, ki, max_kp, max_ki, max_speed_m_s, dead_band_m, integral_dead_band_m, "
                   "output_limit, velocity_feedforward, min_gain_margin_db, min_phase_margin_deg, plants, "
                   "acceleration_feedforward, jerk_feedforward");
  }
  {
    const std::string text = "lcm_uri = \"udpm://\"\n" + std::string(kMinimal);
    expect_message(error_of(text), 1, "lcm_uri", "unknown key, expected one of: lcm_url,");
  }
  {
    const std::string text = replace(kMinimal, "plugin = \"sim\"", "plugin = \"sim\"\nplugins = \"x\"");
    expect_message(error_of(text), line_of(text, "plugins"), "drivers[0].plugins",
                   "unknown key, expected one of: name, plugin, settings");
  }
  {
    const std::string text = replace(kMinimal, "channel = \"valve_enable\"",
                                     "channel = \"valve_enable\"\nscale = 2");
    expect_message(error_of(text), line_of(text, "scale = 2"), "axes[0].signals.valve_enable.scale",
                   "unknown key, expected one of: driver, channel, invert");
  }
  {
    const std::string text = replace(kMinimal, "[axes.signals.pressure_b]", "[axes.signals.presure_b]");
    expect_message(error_of(text), line_of(text, "presure_b"), "axes[0].signals.presure_b",
                   "unknown key, expected one of: position, pressure_a, pressure_b, spool");
  }
  {
    const std::string text = replace(kMinimal, "encoder_jump_m = 0.005", "encoder_jump_m = 0.005\nstale = 3");
    expect_message(error_of(text), line_of(text, "stale = 3"), "axes[0].safety.stale",
                   "unknown key, expected one of: max_pressure_pa,");
  }
}

// Thresholds that are times are given in seconds; the old count of base ticks is refused with
// what replaced it, so a configuration written for it cannot silently change meaning.
TEST(DaemonConfigErrors, EncoderStaleCyclesIsRefusedWithItsReplacement) {
  const std::string text = replace(kMinimal, "encoder_jump_m = 0.005", "encoder_jump_m = 0.005\nencoder_stale_cycles = 10");
  expect_message(error_of(text), line_of(text, "encoder_stale_cycles"), "axes[0].safety.encoder_stale_cycles",
                 "encoder_stale_s instead: thresholds that are times are given in seconds");
}

// Scaling lives on the driver channel (value = raw * scale + offset). A signal table that still
// scales, with the old second stage's keys (which subtracted the offset), is refused with what
// changed, so an old configuration cannot silently flip a sign.
TEST(DaemonConfigErrors, ASignalThatStillScalesIsRefusedWithWhatChanged) {
  for (const std::string key : {"scale", "offset"}) {
    SCOPED_TRACE(key);
    const std::string text = replace(kMinimal, "channel = \"pressure_a\"\n", "channel = \"pressure_a\"\n" + key + " = 2\n");
    expect_message(error_of(text), line_of(text, key + " = 2"), "axes[0].signals.pressure_a." + key,
                   "expected no " + key + " here: a signal no longer scales; set scale and offset on the driver's "
                   "channel, where value = raw * scale + offset");
  }
}

TEST(DaemonConfigErrors, MissingRequiredKey) {
  {
    const std::string text = replace(kMinimal, "ki = 460.0\n", "");
    expect_message(error_of(text), line_of(text, "[axes.pi]"), "axes[0].pi.ki",
                   "required key is missing, expected a finite number in [0, 1000000]");
  }
  {
    const std::string text = replace(kMinimal, "drive = \"direct\"\n", "");
    expect_message(error_of(text), line_of(text, "[[axes]]"), "axes[0].drive",
                   "required key is missing, expected \"direct\" or \"proportional\"");
  }
  {
    const std::string text =
        replace(kMinimal, "[axes.limits]\nsoft_min_m = 0.01\nsoft_max_m = 0.29\n", "");
    expect_message(error_of(text), line_of(text, "[[axes]]"), "axes[0].limits",
                   "required key is missing, expected a table [axes[0].limits]");
  }
  {
    const std::string text = replace(kMinimal, "[axes.signals.valve_enable]\ndriver = \"rig\"\nchannel = \"valve_enable\"\n", "");
    const std::string message = error_of(text);
    expect_message(message, line_of(text, "[axes.signals.position]"), "axes[0].signals.valve_enable",
                   "required key is missing, expected a table [axes[0].signals.valve_enable]");
  }
  {
    const std::string text = replace(kMinimal, "channel = \"pressure_b\"\n", "");
    expect_message(error_of(text), line_of(text, "[axes.signals.pressure_b]"),
                   "axes[0].signals.pressure_b.channel",
                   "required key is missing, expected the name of one of the driver's channels");
  }
  {
    const std::string text(kMinimal.substr(0, kMinimal.find("[[axes]]")));
    expect_message(error_of(text), 1, "axes", "required key is missing, expected at least one [[axes]] table");
  }
  {
    const std::string text(kMinimal.substr(kMinimal.find("[[axes]]")));
    expect_message(error_of(text), 1, "drivers",
                   "required key is missing, expected at least one [[drivers]] table");
  }
}

TEST(DaemonConfigErrors, DuplicateName) {
  {
    const std::string second(kMinimal.substr(kMinimal.find("[[axes]]")));
    const std::string text = std::string(kMinimal) + "\n" + second;
    expect_message(error_of(text), last_line_of(text, "name = \"x\""), "axes[1].name",
                   "a name no other axis has (axes[0] is already called \"x\"), got \"x\"");
  }
  {
    const std::string text = "[[drivers]]\nname = \"rig\"\nplugin = \"other\"\n" + std::string(kMinimal);
    expect_message(error_of(text), 5, "drivers[1].name",
                   "a name no other driver has (drivers[0] is already called \"rig\"), got \"rig\"");
  }
}

// The RT cycle's driver-failure masks have a bit per driver instance: the 65th [[drivers]] table is
// refused where it starts, and 64 load.
TEST(DaemonConfigErrors, AtMost64DriverInstances) {
  auto with_extra_drivers = [](int extra) {
    std::string text(kMinimal);
    for (int i = 0; i < extra; ++i) text = "[[drivers]]\nname = \"aux" + std::to_string(i) + "\"\nplugin = \"sim\"\n" + text;
    return text;
  };
  ASSERT_EQ(kMaxDriverInstances, 64u);
  EXPECT_EQ(parse_config(with_extra_drivers(63), "test.toml").drivers.size(), 64u);
  const std::string text = with_extra_drivers(64);
  // kMinimal's own [[drivers]] table comes 65th, after the 64 added before it.
  expect_message(error_of(text), line_of(text, "[[drivers]]\nname = \"rig\""), "drivers[64]",
                 "one [[drivers]] table too many: hsad runs at most 64 driver instances");
}

TEST(DaemonConfigErrors, UnknownDriverReference) {
  const std::string text = replace(kMinimal, "driver = \"rig\"\nchannel = \"pressure_a\"",
                                   "driver = \"rigg\"\nchannel = \"pressure_a\"");
  expect_message(error_of(text), line_of(text, "\"rigg\""), "axes[0].signals.pressure_a.driver",
                 "expected the name of a configured driver (one of: rig), got \"rigg\"");
}

TEST(DaemonConfigErrors, RateThatDoesNotDivideTheBaseRate) {
  {
    const std::string text = replace(kMinimal, "drive = \"direct\"", "drive = \"direct\"\ncylinder_rate_hz = 3000");
    expect_message(error_of(text), line_of(text, "cylinder_rate_hz"), "axes[0].cylinder_rate_hz",
                   "expected a rate in Hz that divides the base rate of 10000 Hz (realtime.base_period_us "
                   "= 100) exactly, got 3000");
  }
  {
    const std::string text = replace(kMinimal, "drive = \"direct\"", "drive = \"direct\"\ntelemetry_rate_hz = 20000");
    expect_message(error_of(text), line_of(text, "telemetry_rate_hz"), "axes[0].telemetry_rate_hz",
                   "divides the base rate of 10000 Hz");
  }
  {
    // The default 1 kHz does not divide a 3333.3 Hz base rate either.
    const std::string text = "[realtime]\nbase_period_us = 300\n" + std::string(kMinimal);
    expect_message(error_of(text), line_of(text, "[[axes]]"), "axes[0].cylinder_rate_hz",
                   "required key is missing, expected a rate in Hz that divides the base rate");
  }
}

TEST(DaemonConfigErrors, ProportionalDriveNeedsTheSpoolAndTheValveLaw) {
  {
    const std::string text = replace(kProportional, "[axes.signals.spool]\ndriver = \"rig\"\nchannel = \"spool_lvdt\"\n", "");
    expect_message(error_of(text), line_of(text, "[axes.signals.position]"), "axes[0].signals.spool",
                   "required key is missing, expected a table [axes[0].signals.spool] binding the spool "
                   "position input (drive = \"proportional\" needs it)");
  }
  {
    const std::string text = replace(kProportional, "[axes.valve_law]\nbias_current_a = 1.5\nproportional_a_per_m = 3300.0\n", "");
    expect_message(error_of(text), line_of(text, "[[axes]]"), "axes[0].valve_law",
                   "required key is missing, expected a table [axes[0].valve_law]");
  }
  {
    const std::string text = replace(kMinimal, "[axes.limits]", "[axes.valve_law]\nbias_current_a = 1.0\n[axes.limits]");
    expect_message(error_of(text), line_of(text, "[axes.valve_law]"), "axes[0].valve_law",
                   "expected no valve_law table with drive = \"direct\"");
  }
  {
    const std::string text = replace(kProportional, "bias_current_a = 1.5", "bias_current_a = 1.5\npredictor_gamma = [0.4, 0.4, 1.5, 0.04]");
    expect_message(error_of(text), line_of(text, "predictor_gamma"), "axes[0].valve_law.predictor_gamma",
                   "expected an array of 4 numbers in (0, 1], got an array");
  }
}

TEST(DaemonConfigErrors, TwoSignalsCannotDriveOneOutput) {
  std::string second(kMinimal.substr(kMinimal.find("[[axes]]")));
  second = replace(second, "name = \"x\"", "name = \"y\"");
  const std::string text = std::string(kMinimal) + second;
  expect_message(error_of(text), last_line_of(text, "channel = \"opening_cmd\""),
                 "axes[1].signals.valve_command.channel",
                 "expected a channel no other output uses (axes[0].signals.valve_command already drives "
                 "'opening_cmd' of driver 'rig'), got \"opening_cmd\"");
}

TEST(DaemonConfigErrors, MissingFileIsNamed) {
  try {
    (void)load_config("/nonexistent/hsad.toml");
    FAIL() << "no error";
  } catch (const io::ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/hsad.toml: cannot open the configuration"));
  }
}

TEST(DaemonConfigErrors, LoadConfigNamesTheFileItRead) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("hsa_test_config_" + std::to_string(::getpid()) + ".toml");
  {
    std::ofstream out(path);
    out << replace(kMinimal, "kp = 85.0", "kp = -3");
  }
  try {
    (void)load_config(path);
    ADD_FAILURE() << "no error";
  } catch (const io::ConfigError& e) {
    EXPECT_THAT(e.what(), ::testing::StartsWith(path.string() + ":" +
                                                std::to_string(line_of(kMinimal, "kp = 85.0")) + ":6: "));
    EXPECT_THAT(e.what(), HasSubstr("axes[0].pi.kp: expected a finite number in (0, 10000], got -3"));
  }
  std::filesystem::remove(path);
}

// The input table (daemon/supervisor/axis_inputs.hpp) and the reader agree: every input of the
// table is a key of [axes.signals] that is read into its member and described, and leaving it out
// is refused or accepted as its presence says.
TEST(DaemonConfig, EveryInputOfTheTableIsReadDescribedAndRequiredAsTheTableSays) {
  const auto table = [](std::string_view key) {
    return "[axes.signals." + std::string(key) + "]\ndriver = \"rig\"\nchannel = \"ch_" + std::string(key) + "\"\n";
  };
  std::string inputs;
  for (const AxisInputInfo& input : kAxisInputs) inputs += table(input.key);
  // The proportional axis, whose law needs every input of presence `law`, with every input bound.
  const std::size_t from = kProportional.find("[axes.signals.position]");
  const std::size_t to = kProportional.find("[axes.signals.valve_command]");
  const std::string all =
      std::string(kProportional.substr(0, from)) + inputs + std::string(kProportional.substr(to));

  const DaemonConfig c = parse_config(all, "test.toml");
  const AxisSignalConfig& s = c.axes.at(0).signals;
  std::size_t read = 0;
#define HSA_EXPECT_READ(signal, name, kind, presence, unreadable)                  \
  if (const auto* x = present(s.signal); x != nullptr && x->channel == "ch_" #signal) { \
    ++read;                                                                          \
  } else {                                                                           \
    ADD_FAILURE() << #signal " was not read";                                        \
  }
  HSA_AXIS_INPUTS(HSA_EXPECT_READ)
#undef HSA_EXPECT_READ
  EXPECT_EQ(read, kAxisInputCount);

  const std::string summary = describe(c);
  const std::string unknown = error_of(replace(all, "[axes.signals.position]", "[axes.signals.nonsense]"));
  for (const AxisInputInfo& input : kAxisInputs) {
    const std::string key(input.key);
    EXPECT_THAT(summary, HasSubstr("\n    " + key + " ")) << summary;
    EXPECT_THAT(summary, HasSubstr(" rig/ch_" + key + "\n")) << summary;
    EXPECT_THAT(unknown, HasSubstr(key)) << unknown;

    const std::string without = replace(all, table(input.key), "");
    if (input.presence == InputPresence::optional) {
      EXPECT_NO_THROW((void)parse_config(without, "test.toml")) << key;
    } else {
      expect_message(error_of(without), line_of(without, "[axes.signals."), "axes[0].signals." + key,
                     "required key is missing, expected a table [axes[0].signals." + key + "]");
    }
  }
}

class ExampleConfig : public ::testing::TestWithParam<const char*> {};

TEST_P(ExampleConfig, Parses) {
  const std::string path = std::string(HSA_SOURCE_DIR) + "/systemd/" + GetParam();
  DaemonConfig c;
  ASSERT_NO_THROW(c = load_config(path));
  ASSERT_FALSE(c.axes.empty());
  for (const AxisConfig& a : c.axes) EXPECT_NO_THROW(control::Cascade{cascade_of(a)}) << a.name;
  const std::string summary = describe(c);
  for (const AxisConfig& a : c.axes) EXPECT_THAT(summary, HasSubstr("HSA/" + a.name + "/")) << summary;
  for (const DriverConfig& d : c.drivers) EXPECT_THAT(summary, HasSubstr(d.name)) << summary;
}

INSTANTIATE_TEST_SUITE_P(Systemd, ExampleConfig,
                         ::testing::Values("hsad-sim.toml", "hsad-sim-two-axes.toml",
                                           "hsad-sim-proportional.toml", "hsad-sim-custom-rig.toml",
                                           "hsad-modbus-simdev.toml",
                                           "hsad-socketcan.toml", "hsad-gpiod.toml"),
                         [](const auto& info) {
                           std::string name = info.param;
                           name = name.substr(0, name.find('.'));
                           for (char& ch : name) ch = (ch == '-') ? '_' : ch;
                           return name;
                         });

// A rig that silently runs without SCHED_FIFO and locked memory is the failure LinuxCNC users
// report most: the examples that drive hardware refuse to start without them. The simulated rigs
// (also the one hsa-simdev serves over Modbus, which the tests run in shared VMs) may run without.
TEST(ExampleConfigs, HardwareExamplesRequireRealTime) {
  const std::string dir = std::string(HSA_SOURCE_DIR) + "/systemd/";
  for (const char* hardware : {"hsad-socketcan.toml", "hsad-gpiod.toml"}) {
    EXPECT_TRUE(load_config(dir + hardware).realtime.require_realtime) << hardware;
  }
}

TEST(ExampleConfigs, HoldWhatTheyDocument) {
  const std::string dir = std::string(HSA_SOURCE_DIR) + "/systemd/";
  const DaemonConfig sim = load_config(dir + "hsad-sim.toml");
  ASSERT_EQ(sim.axes.size(), 1u);
  EXPECT_EQ(sim.axes[0].law->name(), "direct");
  EXPECT_EQ(sim.drivers[0].plugin, "sim");
  EXPECT_EQ(sim.drivers[0].settings["valve"].value<std::string>(), "servo");
  ASSERT_TRUE(sim.axes[0].signals.estop.has_value());
  EXPECT_TRUE(sim.axes[0].signals.estop->params.invert);

  const DaemonConfig two = load_config(dir + "hsad-sim-two-axes.toml");
  ASSERT_EQ(two.axes.size(), 2u);
  ASSERT_EQ(two.drivers.size(), 2u);
  EXPECT_NE(two.axes[0].name, two.axes[1].name);
  EXPECT_NE(two.axes[0].signals.position.driver, two.axes[1].signals.position.driver);

  const DaemonConfig prop = load_config(dir + "hsad-sim-proportional.toml");
  ASSERT_EQ(prop.axes.size(), 1u);
  EXPECT_EQ(prop.axes[0].law->name(), "proportional");
  ASSERT_TRUE(prop.axes[0].signals.spool.has_value());
  EXPECT_EQ(prop.drivers[0].settings["valve"].value<std::string>(), "proportional");
  EXPECT_EQ(prop.axes[0].safety.safe_valve_command, cascade_of(prop.axes[0]).valve.bias_current_a);

  // Both simulated-rig examples park the PI's integrator near the setpoint, as the experiments do,
  // and the proportional one carries the valve-law preset it says it does.
  EXPECT_EQ(cascade_of(sim.axes[0]).cylinder.integral_dead_band_m, 5e-6);
  EXPECT_EQ(cascade_of(prop.axes[0]).cylinder.integral_dead_band_m, 5e-6);
  const control::ValveLawParams& v = cascade_of(prop.axes[0]).valve;
  const control::ValveLawParams preset = control::simulated_proportional_valve_law();
  EXPECT_EQ(v.bias_current_a, preset.bias_current_a);
  EXPECT_EQ(v.max_current_a, preset.max_current_a);
  EXPECT_EQ(v.feedforward_a_per_m, preset.feedforward_a_per_m);
  EXPECT_EQ(v.integral_a_per_m_s, preset.integral_a_per_m_s);
  EXPECT_EQ(v.proportional_a_per_m, preset.proportional_a_per_m);
  EXPECT_EQ(v.dead_band_compensation_a, preset.dead_band_compensation_a);
  EXPECT_EQ(v.dead_band_error_m, preset.dead_band_error_m);
  EXPECT_EQ(v.velocity_a_per_m_s, preset.velocity_a_per_m_s);
  EXPECT_EQ(v.acceleration_a_per_m_s2, preset.acceleration_a_per_m_s2);
  EXPECT_EQ(v.dither_amplitude_a, preset.dither_amplitude_a);
  EXPECT_EQ(v.dither_frequency_hz, preset.dither_frequency_hz);
}

}  // namespace
}  // namespace hsa::daemon

namespace hsa::daemon {
namespace {

// ---- what is unsafe is refused (config_bounds.hpp) ----------------------------------------------

TEST(DaemonConfigUnsafe, ASafeValveCommandThatOpensTheValveIsRefused) {
  for (const std::string value : {"1", "-0.5", "0.03"}) {
    SCOPED_TRACE(value);
    const std::string text = kMinimal.data() + std::string("safe_valve_command = ") + value + "\n";
    expect_message(error_of(text), line_of(text, "safe_valve_command"), "axes[0].safety.safe_valve_command",
                   "expected a finite number in [-0.02, 0.02], got " + value);
  }
  // A wider band is a deliberate line, and it has a ceiling.
  const std::string wide = kMinimal.data() + std::string("safe_valve_command = 0.05\nsafe_command_band = 0.05\n");
  EXPECT_EQ(parse_config(wide, "t.toml").axes[0].safety.safe_valve_command, 0.05);
  const std::string too_wide = kMinimal.data() + std::string("safe_command_band = 0.5\n");
  expect_message(error_of(too_wide), line_of(too_wide, "safe_command_band"), "axes[0].safety.safe_command_band",
                 "expected a finite number in [0, 0.1], got 0.5");
}

TEST(DaemonConfigUnsafe, AProportionalValvesSafeCurrentIsTheNullOrDeEnergized) {
  // Null current 1.5 A, max 3 A (control/'s default), band 0.02 of it: 0.06 A.
  EXPECT_EQ(parse_config(kProportional, "t.toml").axes[0].safety.safe_valve_command, 1.5);
  const std::string off = kProportional.data() + std::string("safe_valve_command = 0.0\n");
  EXPECT_EQ(parse_config(off, "t.toml").axes[0].safety.safe_valve_command, 0.0);
  const std::string open = kProportional.data() + std::string("safe_valve_command = 2.5\n");
  expect_message(error_of(open), line_of(open, "safe_valve_command"), "axes[0].safety.safe_valve_command",
                 "a current that closes the valve: 0 A (de-energized) or within 0.06 A of the null current "
                 "valve_law.bias_current_a = 1.5 A");
}

TEST(DaemonConfigUnsafe, SoftLimitsOutsideThePositionSensorsRangeAreRefused) {
  const std::string ranged =
      replace(kMinimal, "channel = \"encoder\"\n", "channel = \"encoder\"\nlow_limit = 0.0\nhigh_limit = 0.3\n");
  EXPECT_NO_THROW((void)parse_config(ranged, "t.toml"));
  const std::string high = replace(ranged, "soft_max_m = 0.29", "soft_max_m = 0.35");
  expect_message(error_of(high), line_of(high, "soft_max_m"), "axes[0].limits.soft_max_m",
                 "a limit inside the position sensor's range [0, 0.3] m (signals.position)");
  const std::string low = replace(ranged, "soft_min_m = 0.01", "soft_min_m = -0.01");
  expect_message(error_of(low), line_of(low, "soft_min_m"), "axes[0].limits.soft_min_m",
                 "a limit inside the position sensor's range [0, 0.3] m (signals.position)");
}

TEST(DaemonConfigUnsafe, AbsurdGainsPressuresAndTimeoutsAreRefusedWithTheirBounds) {
  const std::tuple<std::string, std::string, std::string, std::string> cases[] = {
      {"kp = 85.0", "kp = 1e300", "axes[0].pi.kp", "(0, 10000]"},
      {"ki = 460.0", "ki = 1e300", "axes[0].pi.ki", "[0, 1000000]"},
      {"max_pressure_pa = 30e5", "max_pressure_pa = 1e300", "axes[0].safety.max_pressure_pa", "(0, 70000000]"},
      {"max_following_error_m = 0.02", "max_following_error_m = 1e300", "axes[0].safety.max_following_error_m",
       "(0, 1]"},
  };
  for (const auto& [from, to, key, range] : cases) {
    SCOPED_TRACE(to);
    const std::string text = replace(kMinimal, from, to);
    expect_message(error_of(text), line_of(text, to), key, "expected a finite number in " + range + ", got 1e+300");
  }
  const std::string timeout = kMinimal.data() + std::string("setpoint_timeout_s = 1e300\n");
  expect_message(error_of(timeout), line_of(timeout, "setpoint_timeout_s"), "axes[0].safety.setpoint_timeout_s",
                 "expected a finite number in (0, 10], got 1e+300");
}

// The gain gate (control/gain_gate.hpp): configured gains that close an unstable loop on a plant
// of Table A3, or one under the minimum margins, refuse the configuration with the file, the line
// of kp, the key and the worst plant; both laws are judged.
TEST(DaemonConfigUnsafe, ConfiguredGainsThatFailTheGainGateAreRefusedNamingTheWorstPlant) {
  for (const std::string_view base : {kMinimal, kProportional}) {
    const std::string text = replace(base, "kp = 85.0", "kp = 400.0");
    expect_message(error_of(text), line_of(text, "kp = 400.0"), "axes[0].pi.kp",
                   "expected gains that pass the gain gate (with ki 460 they are refused: unstable on plant "
                   "6 kg / 290 mm (GM -1.19 dB)");
  }
  {
    const std::string text = replace(kMinimal, "kp = 85.0", "kp = 120.0");
    expect_message(error_of(text), line_of(text, "kp = 120.0"), "axes[0].pi.kp",
                   "gain margin 9.04 dB on plant 6 kg / 290 mm below the minimum 11 dB (min_gain_margin_db)");
  }
  {
    const std::string text = replace(kMinimal, "ki = 460.0", "ki = 460.0\nmin_phase_margin_deg = 62");
    expect_message(error_of(text), line_of(text, "kp = 85.0"), "axes[0].pi.kp",
                   "phase margin 60.98° on plant 6 kg / 150 mm below the minimum 62°");
  }
}

// An axis's own plant set (`plants`, a file from `hsa-analyze identify --set`) replaces Table A3
// in its gate: the custom rig's two identified plants (tests/daemon/data, written by
// tools/commission-demo) take gains the paper's table refuses, and a missing file or one that is
// not a plant set is refused naming the key.
TEST(DaemonConfig, AnIdentifiedPlantSetReplacesTableA3InTheGate) {
  const std::string set = std::string(HSA_SOURCE_DIR) + "/tests/daemon/data/custom-rig-plants.toml";
  // 0.09 m/s: within the set's capability (retracting 0.0914 m/s; test_config_capability.cpp).
  const std::string text = replace(replace(replace(kMinimal, "kp = 85.0", "kp = 120.0"), "ki = 460.0",
                                           "ki = 460.0\nplants = \"" + set + "\""),
                                   "max_speed_m_s = 0.2", "max_speed_m_s = 0.09");
  const DaemonConfig c = parse_config(text, "t.toml");  // GM 15.4 dB there; 9.0 dB on Table A3
  EXPECT_THAT(describe(c), HasSubstr(set));
  EXPECT_NO_THROW(c.axes[0].law->check_gains({.kp = 170.0, .ki = 460.0}));  // GM 12.5 dB there, 6.1 on Table A3
  try {
    c.axes[0].law->check_gains({.kp = 240.0, .ki = 460.0});  // max_kp, GM 9.3 dB there
    ADD_FAILURE() << "kp 240 passed the gate";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("on plant 0 kg / 200 mm below the minimum 11 dB"));
  }
  const std::string missing = replace(kMinimal, "ki = 460.0", "ki = 460.0\nplants = \"/nonexistent/plants.toml\"");
  EXPECT_THAT(error_of(missing), HasSubstr("axes[0].pi.plants: expected a plant-set file hsa can read ("));
  const std::string not_a_set = replace(kMinimal, "ki = 460.0", "ki = 460.0\nplants = \"" + std::string(HSA_SOURCE_DIR) +
                                                                     "/systemd/hsad-sim.toml\"");
  EXPECT_THAT(error_of(not_a_set), HasSubstr("axes[0].pi.plants: expected a plant-set file hsa can read ("));
}

// feedforward = "plants": the feed-forward follows the gate's plant set over the stroke (Table A3,
// or the axis's own set); it takes no fixed gain beside it, and any other word is refused.
TEST(DaemonConfig, FeedforwardFromThePlantsFollowsTheGatesPlantSet) {
  const auto schedule_of = [](const DaemonConfig& c) {
    return dynamic_cast<const control::PiCascadeLaw&>(*c.axes[0].law).cascade().params().cylinder.feedforward_schedule;
  };
  const DaemonConfig fixed = parse_config(kMinimal, "t.toml");
  EXPECT_TRUE(schedule_of(fixed).empty());
  const DaemonConfig a3 = parse_config(replace(kMinimal, "ki = 460.0", "ki = 460.0\nfeedforward = \"plants\""), "t.toml");
  EXPECT_EQ(schedule_of(a3).count, 11u);
  EXPECT_THAT(describe(a3), HasSubstr("following the plant set's working points"));
  const std::string set = std::string(HSA_SOURCE_DIR) + "/tests/daemon/data/custom-rig-plants.toml";
  const DaemonConfig own = parse_config(
      replace(replace(kMinimal, "ki = 460.0", "ki = 460.0\nfeedforward = \"plants\"\nplants = \"" + set + "\""),
              "max_speed_m_s = 0.2", "max_speed_m_s = 0.09"),
      "t.toml");
  ASSERT_EQ(schedule_of(own).count, 2u);  // the custom rig's 200 and 300 mm plants
  EXPECT_NEAR(schedule_of(own).at(0.2).velocity, 1.0 / 0.15117, 0.01);
  EXPECT_NEAR(schedule_of(own).at(0.3).velocity, 1.0 / 0.16736, 0.01);

  EXPECT_THAT(error_of(replace(kMinimal, "ki = 460.0", "ki = 460.0\nfeedforward = \"plants\"\nvelocity_feedforward = 4.0")),
              HasSubstr("axes[0].pi.velocity_feedforward: expected no fixed feed-forward gain with feedforward = \"plants\""));
  EXPECT_THAT(error_of(replace(kMinimal, "ki = 460.0", "ki = 460.0\nfeedforward = \"plant\"")),
              HasSubstr("axes[0].pi.feedforward: expected \"gains\" (the three *_feedforward gains) or \"plants\""));
  EXPECT_THAT(error_of(replace(kMinimal, "ki = 460.0", "ki = 460.0\nfeedforward = 1")),
              HasSubstr("axes[0].pi.feedforward: expected \"gains\""));
}

// The minimums are read from [axes.pi] within their bounds; lowered, they let a pair through that
// the defaults refuse, and every runtime gain pair is judged with them.
TEST(DaemonConfig, GainGateMinimumsAreReadAndJudgeRuntimeGains) {
  const DaemonConfig c = parse_config(
      replace(kMinimal, "ki = 460.0", "ki = 460.0\nmin_gain_margin_db = 9\nmin_phase_margin_deg = 45"), "t.toml");
  EXPECT_NO_THROW(c.axes[0].law->check_gains({.kp = 70.0, .ki = 400.0}));  // PM 59.7°: under the default
  try {
    c.axes[0].law->check_gains({.kp = 170.0, .ki = 460.0});  // within max_kp, GM 6.1 dB
    ADD_FAILURE() << "kp 170 passed the gate";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("gain margin 6.11 dB on plant 6 kg / 290 mm below the minimum 9 dB"));
  }
  EXPECT_THAT(describe(c), HasSubstr("33 plants of Table A3, gain margin >= 9 dB, phase margin >= 45 deg"));

  const DaemonConfig defaults = parse_config(kMinimal, "t.toml");
  EXPECT_THROW(defaults.axes[0].law->check_gains({.kp = 70.0, .ki = 400.0}), std::invalid_argument);
  EXPECT_NO_THROW(defaults.axes[0].law->check_gains({.kp = 85.0, .ki = 460.0}));
  // Each running axis gets a clone of the configuration's law: the clone keeps the gate.
  EXPECT_THROW(defaults.axes[0].law->clone()->check_gains({.kp = 70.0, .ki = 400.0}), std::invalid_argument);
  EXPECT_THAT(describe(defaults), HasSubstr("gain margin >= 11 dB, phase margin >= 60 deg, ||W1 T0||inf <= 1"));

  for (const auto& [line, key, expected] :
       {std::tuple{"min_gain_margin_db = -1", "min_gain_margin_db", "expected a finite number in [0, 40], got -1"},
        std::tuple{"min_phase_margin_deg = 90", "min_phase_margin_deg", "expected a finite number in [0, 90), got 90"}}) {
    SCOPED_TRACE(line);
    const std::string text = replace(kMinimal, "ki = 460.0", std::string("ki = 460.0\n") + line);
    expect_message(error_of(text), line_of(text, line), std::string("axes[0].pi.") + key, expected);
  }
}

TEST(DaemonConfigUnsafe, LcmUrlsThatLeaveTheLocalSegmentAreRefusedUnlessAllowed) {
  for (const std::string url : {"udpm://239.255.76.67:7667?ttl=255", "udpm://192.168.1.20:7667?ttl=0",
                                "file:///tmp/x.log?mode=w", "memq://", "udpm://239.255.76.67:7667?ttl=2"}) {
    SCOPED_TRACE(url);
    const std::string text = "lcm_url = \"" + url + "\"\n" + kMinimal.data();
    expect_message(error_of(text), 1, "lcm_url",
                   "a udpm:// URL on a multicast group (224.0.0.0/4) with ttl=0 or ttl=1 (or allow_routed_lcm = true)");
    const std::string allowed = "allow_routed_lcm = true\n" + text;
    EXPECT_EQ(parse_config(allowed, "t.toml").lcm_url, url);
  }
  for (const std::string url : {"udpm://239.255.76.67:7667?ttl=1", "udpm://239.255.76.67:7667",
                                "udpm://224.0.0.251:7667?recv_buf_size=1000&ttl=0"}) {
    EXPECT_EQ(parse_config("lcm_url = \"" + url + "\"\n" + kMinimal.data(), "t.toml").lcm_url, url);
  }
}

TEST(DaemonConfig, AuthenticationIsOnUnlessTheFileTurnsItOff) {
  const DaemonConfig c = parse_config(
      std::string(kMinimal) +
          "\n[auth]\nrequire_auth = false\nkey_dir = \"/srv/keys\"\nstamp_window_s = 0.5\nlease_timeout_s = 120\n",
      "t.toml");
  EXPECT_FALSE(c.auth.require_auth);
  EXPECT_EQ(c.auth.key_dir, "/srv/keys");
  EXPECT_EQ(c.auth.stamp_window_s, 0.5);
  EXPECT_EQ(c.auth.lease_timeout_s, 120.0);
  {
    const std::string text = std::string(kMinimal) + "\n[auth]\nrequire = false\n";
    expect_message(error_of(text), line_of(text, "require ="), "auth.require",
                   "unknown key, expected one of: require_auth, key_dir, stamp_window_s, lease_timeout_s, system_name");
  }
  EXPECT_EQ(parse_config(std::string(kMinimal) + "\n[auth]\nsystem_name = \"rig-a.lab_2\"\n", "t.toml").auth.system_name,
            "rig-a.lab_2");
  for (const char* name : {"\"\"", "\"rig a\"", "\"rig/a\"", "\"\\u00e9t\u00e9\"", "42",
                           "\"0123456789012345678901234567890123456789012345678901234567890123456789\""}) {
    const std::string text = std::string(kMinimal) + "\n[auth]\nsystem_name = " + name + "\n";
    expect_message(error_of(text), line_of(text, "system_name"), "auth.system_name",
                   "a system name of 1 to 64 letters, digits, '.', '_' and '-' (default: the host name)");
  }
  for (const char* window : {"0", "-1", "61", "nan"}) {
    const std::string text = std::string(kMinimal) + "\n[auth]\nstamp_window_s = " + window + "\n";
    expect_message(error_of(text), line_of(text, "stamp_window_s"), "auth.stamp_window_s",
                   "expected a finite number in (0, 60]");
  }
  const std::string text = std::string(kMinimal) + "\n[auth]\nkey_dir = \"\"\n";
  expect_message(error_of(text), line_of(text, "key_dir"), "auth.key_dir", "expected a folder of <operator>.key files");
}

TEST(DaemonConfigUnsafe, PluginsAreBareNamesNotPaths) {
  for (const std::string plugin : {"/usr/lib/x86_64-linux-gnu/libc.so.6", "../../../../tmp/evil", "sim.so", ""}) {
    SCOPED_TRACE(plugin);
    const std::string text = replace(kMinimal, "plugin = \"sim\"", "plugin = \"" + plugin + "\"");
    expect_message(error_of(text), line_of(text, "plugin ="), "drivers[0].plugin",
                   "a plugin name of letters, digits, '_' and '-' such as \"sim\" (no path");
  }
}

// The flight recorder's tables (daemon/config/recorder_config_reader.cpp).
TEST(DaemonConfig, RecorderDefaultsAndKeys) {
  const DaemonConfig d = parse_config(kMinimal, "test.toml");
  EXPECT_EQ(d.axes[0].recorder.rows, 20'000u);  // 2 s at 10 kHz
  EXPECT_EQ(d.axes[0].recorder.post_rows, 5'000u);
  EXPECT_EQ(d.recorder.folder, "");  // $STATE_DIRECTORY or /var/lib/hsa when hsad starts
  EXPECT_EQ(d.recorder.max_files, 100u);
  EXPECT_EQ(d.text, kMinimal);
  const std::string text = std::string(kMinimal) + "\n[axes.recorder]\nseconds = 0.5\npost_trigger_s = 0.1\n" +
                           "[recorder]\nfolder = \"/tmp/x\"\nmax_files = 3\n";
  const DaemonConfig c = parse_config(text, "test.toml");
  EXPECT_EQ(c.axes[0].recorder.rows, 5'000u);
  EXPECT_EQ(c.axes[0].recorder.post_rows, 1'000u);
  EXPECT_EQ(c.recorder.folder, "/tmp/x");
  EXPECT_EQ(c.recorder.max_files, 3u);
}

TEST(DaemonConfigErrors, RecorderValuesOutsideTheirRangesNameTheKey) {
  const std::string base = std::string(kMinimal) + "\n[axes.recorder]\n";
  std::string text = base + "seconds = 100\n";
  expect_message(error_of(text), last_line_of(text, "seconds"), "axes[0].recorder.seconds", "[0.0002, 60]");
  text = base + "seconds = 1\npost_trigger_s = 1\n";
  expect_message(error_of(text), last_line_of(text, "post_trigger_s"), "axes[0].recorder.post_trigger_s", "[0, 1)");
  text = base + "second = 1\n";
  EXPECT_THAT(error_of(text), HasSubstr("second")) << error_of(text);
  text = std::string(kMinimal) + "\n[recorder]\nmax_files = 0\n";
  expect_message(error_of(text), last_line_of(text, "max_files"), "recorder.max_files", "1");
}

// The Prometheus textfile (daemon/config/metrics_config_reader.cpp): none without [metrics].
TEST(DaemonConfig, MetricsTextfileIsOffUnlessConfigured) {
  const DaemonConfig d = parse_config(kMinimal, "test.toml");
  EXPECT_FALSE(d.metrics.enabled());
  const std::string text = std::string(kMinimal) +
                           "\n[metrics]\ntextfile = \"/var/lib/prometheus/node-exporter/hsad.prom\"\ninterval_s = 2.5\n";
  const DaemonConfig c = parse_config(text, "test.toml");
  EXPECT_TRUE(c.metrics.enabled());
  EXPECT_EQ(c.metrics.textfile, "/var/lib/prometheus/node-exporter/hsad.prom");
  EXPECT_EQ(c.metrics.interval_s, 2.5);
  const DaemonConfig e = parse_config(std::string(kMinimal) + "\n[metrics]\ntextfile = \"/x/h.prom\"\n", "test.toml");
  EXPECT_EQ(e.metrics.interval_s, 5.0);  // the documented default
}

TEST(DaemonConfigErrors, MetricsValuesNameTheKeyAndWhatWasExpected) {
  const std::string base = std::string(kMinimal) + "\n[metrics]\n";
  // The collector reads only *.prom; a relative path would hang on hsad's working directory.
  for (const char* bad : {"\"/x/hsad.txt\"", "\"hsad.prom\"", "\"/x/.prom\"", "\"\"", "3"}) {
    const std::string text = base + "textfile = " + bad + "\n";
    expect_message(error_of(text), last_line_of(text, "textfile"), "metrics.textfile",
                   "an absolute path ending in \".prom\"");
  }
  std::string text = base + "interval_s = 1\n";  // no textfile
  EXPECT_THAT(error_of(text), HasSubstr("metrics.textfile: required key is missing")) << error_of(text);
  text = base + "textfile = \"/x/h.prom\"\ninterval_s = 0.01\n";
  expect_message(error_of(text), last_line_of(text, "interval_s"), "metrics.interval_s", "[0.1, 3600]");
  text = base + "textfile = \"/x/h.prom\"\nport = 9100\n";
  EXPECT_THAT(error_of(text), HasSubstr("port")) << error_of(text);
}

}  // namespace
}  // namespace hsa::daemon
