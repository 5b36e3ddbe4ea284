// [axes.valve_law.predictive] (the predictive law, control/valve_predictive.hpp, and what its design,
// control/valve_predictive_design.hpp, builds it from, as `hsa-analyze valve-law --step predictive`
// prints it): read into ValveLawParams::predictive as valve_predictive_params() builds it from the
// same figures, shown by `hsad --check-config` (describe) in eq 31's place, and every refusal names
// the file, line, key path and what was expected: a missing or out-of-range key, eq 31's keys and
// tables beside it (they would only look configured), and what the design itself refuses.
#include <string>
#include <string_view>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/valve_predictive_design.hpp"
#include "daemon/config/describe.hpp"
#include "daemon/config/load_config.hpp"
#include "tests/daemon/valve_law_config_test_support.hpp"
#include "tests/support/proportional_axis_toml.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using config_test::error_of;
using config_test::valve_of;

// The identified valve near the paper's (round figures) and the design's settings near its pick for
// that valve.
constexpr std::string_view kPredictive = R"(
[axes.valve_law.predictive]
gain_m_per_a = 0.0018238
rest_position_m = -0.0025
natural_frequency_hz = 50.0
damping_ratio = 0.3
magnetic_lag_s = 0.0015
dead_band_a = 0.3
friction_band_m = 2e-5
delay_s = 0.0003
sensor_bandwidth_hz = 500.0
regulator_delay_s = 0.0002
lvdt_noise_m = 1.03e-6
preview_samples = 16
horizon_extra_samples = 50
rate_weight_m2_per_a2 = 2e-11
dither_fraction = 0.75
dither_frequency_hz = 2500.0
headroom_fraction = 0.5
disturbance_walk_a = 1e-5
held_disturbance_walk_a = 1e-4
velocity_walk_m_s = 1e-5
direction_velocity_m_s = 2e-4
max_qp_iterations = 200
)";

// The same figures as the design reads them.
control::ValvePredictiveValve table_valve(double max_current_a) {
  control::ValvePredictiveValve v;
  v.model.gain_m_per_a = 0.0018238;
  v.model.rest_position_m = -0.0025;
  v.model.natural_frequency_hz = 50.0;
  v.model.damping_ratio = 0.3;
  v.model.magnetic_lag_s = 0.0015;
  v.model.width_a = 0.3;
  v.model.friction_band_m = 2e-5;
  v.model.delay_s = 0.0003;
  v.model.sensor_bandwidth_hz = 500.0;
  v.regulator_delay_s = 0.0002;
  v.lvdt_noise_m = 1.03e-6;
  v.current_max_a = max_current_a;
  return v;
}

control::ValvePredictiveSettings table_settings() {
  control::ValvePredictiveSettings s;
  s.preview_samples = 16;
  s.horizon_extra_samples = 50;
  s.rate_weight_m2_per_a2 = 2e-11;
  s.dither_fraction = 0.75;
  s.headroom_fraction = 0.5;
  s.disturbance_walk_a = 1e-5;
  s.held_disturbance_walk_a = 1e-4;
  s.velocity_walk_m_s = 1e-5;
  s.direction_velocity_m_s = 2e-4;
  s.max_qp_iterations = 200;
  return s;
}

// A proportional axis at a 100 µs base tick whose [axes.valve_law] has the bias (the null command
// the safety chain uses), `outer` and then `predictive`.
std::string config(std::string_view outer, std::string_view predictive = kPredictive) {
  return "[realtime]\nbase_period_us = 100\n" +
         test::proportional_axis_toml("[axes.valve_law]\nbias_current_a = 1.5\n" + std::string(outer) +
                                      std::string(predictive));
}

// kPredictive with the line starting `key =` replaced by `line` (dropped when `line` is empty).
std::string predictive_with(std::string_view key, std::string_view line) {
  return config_test::with_line(kPredictive, key, line);
}

void expect_refused(const std::string& text, std::string_view line_text, std::string_view key,
                    std::string_view expected) {
  SCOPED_TRACE(text.substr(text.find("[axes.valve_law]")));
  config_test::expect_refused_config(text, line_text, key, expected);
}

TEST(ValvePredictiveConfig, TheTableIsTheLawTheDesignBuildsFromTheSameFigures) {
  const DaemonConfig c = parse_config(config("max_current_a = 2.5\nspool_at_full_opening_m = 0.001\n"), "test.toml");
  const control::ValveLawParams& v = valve_of(c);
  ASSERT_TRUE(v.predictive.enabled);
  // I_max is the law's max_current_a, T the base tick as hsad computes it (100 · 1e-6 s).
  EXPECT_EQ(v.predictive, control::valve_predictive_params(table_valve(2.5), c.realtime.base_period_s(), 2500.0,
                                                           table_settings()));
  EXPECT_EQ(v.predictive.delay_samples, 4);  // τ + δ = 0.5 ms = 5 ticks, less the one the command is held over
  EXPECT_EQ(v.predictive.current_max_a, 2.5);
  EXPECT_EQ(v.predictive.dither_half_period_samples, 2);
  // What stays beside it, and eq 31 left at its defaults: it does not run.
  EXPECT_EQ(v.bias_current_a, 1.5);
  EXPECT_EQ(v.max_current_a, 2.5);
  EXPECT_EQ(dynamic_cast<const control::PiCascadeLaw&>(*c.axes[0].law).cascade().params().spool_at_full_opening_m,
            0.001);
  const control::ValveLawParams defaults;
  EXPECT_EQ(v.proportional_a_per_m, defaults.proportional_a_per_m);
  EXPECT_EQ(v.dither_amplitude_a, defaults.dither_amplitude_a);
  EXPECT_FALSE(v.model_predictor.enabled);
  EXPECT_FALSE(v.time_optimal.enabled);
  // Without the table the law is off.
  EXPECT_FALSE(valve_of(parse_config(config("proportional_a_per_m = 3300.0\n", ""), "test.toml")).predictive.enabled);
}

TEST(ValvePredictiveConfig, WithoutADitherItsFrequencyIsRefusedAndNotNeeded) {
  const std::string off = predictive_with("dither_fraction", "dither_fraction = 0.0");
  expect_refused(config("", off), "dither_frequency_hz = 2500.0", "predictive.dither_frequency_hz",
                 "expected no frequency while dither_fraction·dead_band_a is 0 (the dither is off), got 2500");
  std::string without(off);
  const std::string_view frequency = "dither_frequency_hz = 2500.0\n";
  without.erase(without.find(frequency), frequency.size());
  const control::ValvePredictiveParams p = valve_of(parse_config(config("", without), "test.toml")).predictive;
  EXPECT_EQ(p.dither_amplitude_a, 0.0);
  EXPECT_EQ(p.dither_half_period_samples, 0);
  EXPECT_EQ(p.lower_a, 0.0);
}

TEST(ValvePredictiveConfig, CheckConfigDescribesThePredictiveLawInEq31sPlace) {
  const DaemonConfig c = parse_config(config("spool_at_full_opening_m = 0.001\n"), "test.toml");
  const std::string on = describe(c);
  EXPECT_THAT(on, HasSubstr("valve law     the predictive law in eq 31's place (eq 31, its feed-forward, predictor "
                            "and moves do not run):\n                  bias 1.5 A (the null command), max 3 A, full "
                            "opening 0.001 m\n"));
  EXPECT_THAT(on, HasSubstr("predictive    on: P 16 samples of preview (0.0016 s), H 66 samples, D 4 samples of "
                            "delay, commands in [0.1125, 2.8875] A,\n                  dither 0.225 A at 2500 Hz, v_d "
                            "0.0002 m/s, at most 200 QP iterations a tick\n"));
  EXPECT_THAT(on, HasSubstr("designed with rho 2e-11 m^2/A^2, dither 0.75 w (0.5 of it kept off the limits), walks "
                            "1e-05 A (held target 0.0001 A) and 1e-05 m/s a sample,\n"
                            "                  on g 0.0018238 m/A, X_min -0.0025 m, f0 50 Hz, zeta 0.3, tau_a 0.0015 "
                            "s, w 0.3 A,\n                  s_f 2e-05 m, delay 0.0003 s + regulator 0.0002 s, LVDT 500 "
                            "Hz and 1.03e-06 m rms\n"));
  // Eq 31's lines would describe a law that does not run.
  for (const char* line : {"K_r ", "feed-forward  ", "predictor     ", "time-optimal  "}) EXPECT_THAT(on, Not(HasSubstr(line)));
  // The copy the axis swaps in describes the same law.
  EXPECT_EQ(c.axes[0].law->clone()->describe(), c.axes[0].law->describe());
  EXPECT_THAT(describe(parse_config(config("proportional_a_per_m = 3300.0\n", ""), "test.toml")),
              HasSubstr("    predictive    off\n"));
}

TEST(ValvePredictiveConfig, EveryKeyIsRequired) {
  for (const char* key : {"gain_m_per_a", "rest_position_m", "natural_frequency_hz", "damping_ratio", "magnetic_lag_s",
                          "dead_band_a", "friction_band_m", "delay_s", "sensor_bandwidth_hz", "regulator_delay_s",
                          "lvdt_noise_m", "preview_samples", "horizon_extra_samples", "rate_weight_m2_per_a2",
                          "dither_fraction", "dither_frequency_hz", "headroom_fraction", "disturbance_walk_a",
                          "held_disturbance_walk_a", "velocity_walk_m_s", "direction_velocity_m_s", "max_qp_iterations"}) {
    // A missing key is reported at the table's header.
    expect_refused(config("", predictive_with(key, "")), "[axes.valve_law.predictive]",
                   std::string("predictive.") + key, "required key is missing, expected");
  }
}

TEST(ValvePredictiveConfig, NumbersOutOfRangeAreRefused) {
  const struct {
    const char* key;
    const char* value;
    const char* expected;
  } cases[] = {
      {"gain_m_per_a", "nan", "expected a finite number > 0, got nan"},
      {"gain_m_per_a", "-0.0018", "expected a finite number > 0, got -0.0018"},
      {"rest_position_m", "inf", "expected a finite number, got"},
      {"natural_frequency_hz", "0.0", "expected a finite number > 0, got 0"},
      {"damping_ratio", "-0.3", "expected a finite number > 0, got -0.3"},
      {"magnetic_lag_s", "nan", "expected a finite number > 0"},
      {"dead_band_a", "3.5", "expected a finite number in [0, 3], got 3.5"},
      {"friction_band_m", "-2e-5", "expected a finite number >= 0, got -2e-05"},
      {"delay_s", "-1e-4", "expected a finite number >= 0"},
      {"sensor_bandwidth_hz", "0.0", "expected a finite number > 0, got 0"},
      {"regulator_delay_s", "5e-5",
       "expected a finite number >= 0.0001 s, the base tick (eq 1's delay counts the period the command is held over), "
       "got 5e-05"},
      {"lvdt_noise_m", "0.0", "expected a finite number > 0, got 0"},
      {"preview_samples", "0", "expected a finite number in [1, 100], got 0"},
      {"preview_samples", "101", "expected a finite number in [1, 100], got 101"},
      {"preview_samples", "16.5",
       "expected a whole number in [1, 100] (samples of the reference read ahead of the reading's target), got 16.5"},
      {"horizon_extra_samples", "0", "expected a finite number in [1, 100], got 0"},
      {"rate_weight_m2_per_a2", "0.0", "expected a finite number in (0, 1e-08], got 0"},
      {"rate_weight_m2_per_a2", "1e-6", "expected a finite number in (0, 1e-08], got 1e-06"},
      // 0.3 A of play, half the dither kept off the limits and 3 A: a dither of 10·w leaves no current.
      {"dither_fraction", "10.0",
       "expected a finite number in [0, 10): the box keeps headroom_fraction·dither_fraction·dead_band_a off both 0 "
       "and max_current_a = 3 A, and must leave current between them, got 10"},
      {"headroom_fraction", "1.5", "expected a finite number in [0, 1], got 1.5"},
      {"headroom_fraction", "-0.5", "expected a finite number in [0, 1], got -0.5"},
      {"dither_fraction", "-0.5", "expected a finite number >= 0, got -0.5"},
      {"dither_frequency_hz", "3000.0",
       "expected a frequency whose half period is a whole number of 0.0001 s base ticks (5000 Hz, 2500 Hz, 1666.67 Hz"},
      {"disturbance_walk_a", "0.0", "expected a finite number > 0, got 0"},
      {"held_disturbance_walk_a", "-1e-5", "expected a finite number > 0"},
      {"velocity_walk_m_s", "-1e-5", "expected a finite number > 0"},
      {"direction_velocity_m_s", "nan", "expected a finite number > 0"},
      {"max_qp_iterations", "0", "expected a finite number in [1, 1000], got 0"},
      {"max_qp_iterations", "2.5", "expected a whole number in [1, 1000] (the QP's iterations a tick"},
  };
  for (const auto& c : cases) {
    const std::string line = std::string(c.key) + " = " + c.value;
    expect_refused(config("", predictive_with(c.key, line)), line, std::string("predictive.") + c.key, c.expected);
  }
}

// Each key in its range, together they are what valve_predictive_params() refuses: the table is
// named, with the design's reason.
TEST(ValvePredictiveConfig, WhatTheDesignRefusesIsRefusedNamingTheTable) {
  // τ + δ = 2.2 ms is 22 ticks: beyond the 16 commands the delay line holds.
  expect_refused(config("", predictive_with("delay_s", "delay_s = 0.002")), "[axes.valve_law.predictive]", "predictive",
                 "expected settings the predictive law accepts (valve_predictive_params: the delay τ + δ must lie "
                 "between 2 and 17 periods), got a table");
  // τ + δ of one tick leaves no command in the delay line.
  std::string one_tick = predictive_with("delay_s", "delay_s = 0.0");
  one_tick.replace(one_tick.find("regulator_delay_s = 0.0002"), 26, "regulator_delay_s = 0.0001");
  expect_refused(config("", one_tick), "[axes.valve_law.predictive]", "predictive",
                 "(valve_predictive_params: the delay τ + δ must lie between 2 and 17 periods)");
  // H = 190 commands from n = 6 + 4 + 2·101 = 212 states: the product every sample starts with is
  // past the law's budget (about 1.5 s to build: the longest test here).
  std::string long_horizon = predictive_with("preview_samples", "preview_samples = 100");
  long_horizon.replace(long_horizon.find("horizon_extra_samples = 50"), 26, "horizon_extra_samples = 90");
  expect_refused(config("", long_horizon), "[axes.valve_law.predictive]", "predictive",
                 "expected settings whose QP fits its work budget: the product of its H x n = 190 x 212 map, 40280 "
                 "multiply-adds each sample, is more than the 40000 a sample may take (fewer preview_samples or "
                 "horizon_extra_samples), got a table");
  // A disturbance that all but never moves: the filter's Riccati recursion does not settle.
  expect_refused(config("", predictive_with("disturbance_walk_a", "disturbance_walk_a = 1e-15")),
                 "[axes.valve_law.predictive]", "predictive",
                 "expected settings the predictive law accepts (valve_predictive_params: the filter's Riccati "
                 "recursion did not settle)");
}

TEST(ValvePredictiveConfig, Eq31sKeysBesideItAreRefusedNotIgnored) {
  for (const char* line : {"feedforward_a_per_m = 548.0", "integral_a_per_m_s = 1e5", "proportional_a_per_m = 3300.0",
                           "dead_band_compensation_a = 0.15", "dead_band_error_m = 1e-6", "velocity_a_per_m_s = 7.5",
                           "acceleration_a_per_m_s2 = 0.002", "dither_amplitude_a = 0.3",
                           "dither_frequency_hz = 2500.0", "reference_velocity_a_per_m_s = 10.25",
                           "reference_acceleration_a_per_m_s2 = 0.0375", "reference_jerk_a_per_m_s3 = 1.5e-5",
                           "reference_filter_hz = 300.0", "track_filtered_reference = true",
                           "direction_compensation_a = 0.125", "direction_velocity_m_s = 2e-3",
                           "predictor_gamma = [0.4, 0.4, 0.04, 0.04]"}) {
    const std::string key(std::string_view(line).substr(0, std::string_view(line).find(' ')));
    expect_refused(config(std::string(line) + "\n"), line, key,
                   "expected no such key while [axes[0].valve_law.predictive] is present (the predictive law decides "
                   "the current in eq 31's place: eq 31's gains, dither, feed-forward and predictor do not run");
  }
}

// The tables are refused for being there, before any of their keys is read: one key stands for a
// whole table.
TEST(ValvePredictiveConfig, TheModelAndTimeOptimalTablesBesideItAreRefused) {
  constexpr std::string_view kModel = "\n[axes.valve_law.model]\ngain_m_per_a = 0.0018238\n";
  constexpr std::string_view kTimeOptimal = "\n[axes.valve_law.time_optimal]\ntrigger_m = 0.00017\n";
  expect_refused(config(kModel), "[axes.valve_law.model]", "model",
                 "expected no such table while [axes[0].valve_law.predictive] is present (the predictive law runs on "
                 "the identified valve in its own table, and the model predictor does not run), got a table");
  expect_refused(config(std::string(kModel) + std::string(kTimeOptimal)), "[axes.valve_law.model]", "model",
                 "expected no such table while [axes[0].valve_law.predictive]");
  expect_refused(config(kTimeOptimal), "[axes.valve_law.time_optimal]", "time_optimal",
                 "expected no such table while [axes[0].valve_law.predictive] is present (the time-optimal moves are "
                 "eq 31's, which does not run)");
}

TEST(ValvePredictiveConfig, AnUnknownKeyIsRefused) {
  expect_refused(config("", std::string(kPredictive) + "horizon_samples = 66\n"), "horizon_samples",
                 "predictive.horizon_samples", "unknown key, expected one of:");
  EXPECT_THAT(error_of(config("", std::string(kPredictive) + "stroke_max_m = 0.00125\n")),
              HasSubstr("predictive.stroke_max_m: unknown key"));
}

}  // namespace
}  // namespace hsa::daemon
