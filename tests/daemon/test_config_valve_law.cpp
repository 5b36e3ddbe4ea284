// [axes.valve_law]'s model-inverse feed-forward keys (control/valve_law.hpp; the feedforward and
// model_inverse steps of identified_valve_law, as `hsa-analyze valve-law` prints them), and its
// [axes.valve_law.model] and [axes.valve_law.time_optimal] tables (the model-predictor, damped and
// time-optimal steps): each is read into control::ValveLawParams, `hsad --check-config` (describe)
// shows them, and every refusal names the file, line, key path and what was expected.
#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/cascade.hpp"
#include "control/laws/pi_cascade_law.hpp"
#include "daemon/config/describe.hpp"
#include "daemon/config/load_config.hpp"
#include "tests/daemon/valve_law_config_test_support.hpp"
#include "tests/support/proportional_axis_toml.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;

// A proportional axis at a 100 µs base tick, its [axes.valve_law] table the preset-like bias and
// gain plus `valve_law`.
std::string config(std::string_view valve_law) {
  return "[realtime]\nbase_period_us = 100\n" +
         test::proportional_axis_toml("[axes.valve_law]\nbias_current_a = 1.5\nproportional_a_per_m = 3300.0\n" +
                                      std::string(valve_law));
}

using config_test::error_of;
using config_test::valve_of;

// The file and line at the start, then the key path, then what was expected.
void expect_refused(std::string_view valve_law, std::string_view line_text, std::string_view key,
                    std::string_view expected) {
  SCOPED_TRACE(std::string(valve_law));
  config_test::expect_refused_config(config(valve_law), line_text, key, expected);
}

constexpr std::string_view kModelInverse = R"(reference_velocity_a_per_m_s = 10.25
reference_acceleration_a_per_m_s2 = 0.0375
reference_jerk_a_per_m_s3 = 1.5e-5
reference_filter_hz = 300.0
track_filtered_reference = true
direction_compensation_a = 0.125
direction_velocity_m_s = 2e-3)";

TEST(ValveLawConfig, EveryModelInverseKeyIsReadIntoTheLawsParameters) {
  const DaemonConfig c = parse_config(config(kModelInverse), "test.toml");
  const control::ValveLawParams& v = valve_of(c);
  EXPECT_EQ(v.reference_velocity_a_per_m_s, 10.25);
  EXPECT_EQ(v.reference_acceleration_a_per_m_s2, 0.0375);
  EXPECT_EQ(v.reference_jerk_a_per_m_s3, 1.5e-5);
  EXPECT_EQ(v.reference_filter_hz, 300.0);
  EXPECT_TRUE(v.track_filtered_reference);
  EXPECT_EQ(v.direction_compensation_a, 0.125);
  EXPECT_EQ(v.direction_velocity_m_s, 2e-3);
  // The cascade (and its ValveLaw) accepts what the reader let through.
  EXPECT_NO_THROW(control::Cascade{dynamic_cast<const control::PiCascadeLaw&>(*c.axes[0].law).cascade().params()});
}

TEST(ValveLawConfig, WithoutTheKeysTheLawIsEq31Alone) {
  const control::ValveLawParams& v = valve_of(parse_config(config(""), "test.toml"));
  const control::ValveLawParams defaults;
  EXPECT_EQ(v.reference_filter_hz, 0.0);
  EXPECT_EQ(v.reference_velocity_a_per_m_s, 0.0);
  EXPECT_EQ(v.reference_acceleration_a_per_m_s2, 0.0);
  EXPECT_EQ(v.reference_jerk_a_per_m_s3, 0.0);
  EXPECT_FALSE(v.track_filtered_reference);
  EXPECT_EQ(v.direction_compensation_a, 0.0);
  EXPECT_EQ(v.direction_velocity_m_s, defaults.direction_velocity_m_s);
}

TEST(ValveLawConfig, CheckConfigDescribesTheFeedForward) {
  const std::string on = describe(parse_config(config(kModelInverse), "test.toml"));
  EXPECT_THAT(on, HasSubstr("feed-forward  reference filter 300 Hz, K_rv 10.25, K_ra 0.0375, K_rj 1.5e-05"));
  EXPECT_THAT(on, HasSubstr("tracks the filtered reference, direction dI_d 0.125 A over 0.002 m/s"));
  const std::string off = describe(parse_config(config(""), "test.toml"));
  EXPECT_THAT(off, HasSubstr("feed-forward  off (no reference_filter_hz)"));
}

TEST(ValveLawConfig, NegativeOrNonFiniteGainsAreRefused) {
  for (const char* key : {"reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3"}) {
    for (const char* value : {"-1.0", "nan", "inf"}) {
      const std::string line = std::string(key) + " = " + value;
      expect_refused("reference_filter_hz = 300.0\n" + line, line, key, "expected a finite number in [0, 1000000000]");
    }
  }
  expect_refused("reference_filter_hz = 300.0\ndirection_compensation_a = -0.1", "direction_compensation_a", "direction_compensation_a",
                 "expected a finite number in [0, 3], got -0.1");
  expect_refused("reference_filter_hz = 300.0\ndirection_velocity_m_s = 0.0", "direction_velocity_m_s", "direction_velocity_m_s",
                 "expected a finite number > 0, got 0");
  expect_refused("reference_filter_hz = 300.0\ntrack_filtered_reference = 1", "track_filtered_reference",
                 "track_filtered_reference", "expected true or false");
}

TEST(ValveLawConfig, TheReferenceFilterMustBePositiveAndFarBelowNyquist) {
  expect_refused("reference_filter_hz = 0.0", "reference_filter_hz", "reference_filter_hz",
                 "expected a finite number > 0, got 0");
  expect_refused("reference_filter_hz = nan", "reference_filter_hz", "reference_filter_hz", "expected a finite number > 0");
  // 500 Hz at 100 µs is ValveLaw's bound (0.05/T); 6000 Hz is above the 5 kHz Nyquist too.
  EXPECT_EQ(valve_of(parse_config(config("reference_filter_hz = 500.0"), "test.toml")).reference_filter_hz, 500.0);
  for (const char* value : {"501.0", "6000.0"}) {
    const std::string line = std::string("reference_filter_hz = ") + value;
    expect_refused(line, line, "reference_filter_hz",
                   "expected a finite number in (0, 500] Hz: at most 0.05/T for the reference filter's explicit "
                   "update, a tenth of the 5000 Hz Nyquist frequency of the 0.0001 s base tick, got");
  }
  // The bound follows the base tick: at 200 µs, 300 Hz is above 0.05/T = 250 Hz.
  std::string slow = config("reference_filter_hz = 300.0");
  slow.replace(slow.find("base_period_us = 100"), 20, "base_period_us = 200");
  const std::string message = error_of(slow);
  EXPECT_THAT(message, HasSubstr("axes[0].valve_law.reference_filter_hz: expected a finite number in (0, 250] Hz"))
      << message;
}

TEST(ValveLawConfig, TrackingTheFilteredReferenceNeedsTheFilter) {
  expect_refused("track_filtered_reference = true", "track_filtered_reference", "track_filtered_reference",
                 "expected false while reference_filter_hz is absent (there is no filtered reference to track");
  // false without a filter says what the default says.
  EXPECT_FALSE(valve_of(parse_config(config("track_filtered_reference = false"), "test.toml")).track_filtered_reference);
}

TEST(ValveLawConfig, FeedForwardGainsWithoutTheFilterAreRefusedNotIgnored) {
  for (const char* key : {"reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3", "direction_compensation_a"}) {
    const std::string line = std::string(key) + " = 1.0";
    expect_refused(line, line, key, "expected no such key while reference_filter_hz is absent");
  }
}

TEST(ValveLawConfig, AMisspeltKeyIsStillRefused) {
  expect_refused("reference_filter = 300.0", "reference_filter =", "reference_filter",
                 "unknown key, expected one of:");
  EXPECT_THAT(error_of(config("reference_filter = 300.0")), HasSubstr("reference_filter_hz, track_filtered_reference"));
}

// The identified valve of the model-predictor steps (round figures near the paper's valve), and the
// time-optimal moves on it.
constexpr std::string_view kModel = R"(
[axes.valve_law.model]
gain_m_per_a = 0.0018238
rest_position_m = -0.0025
natural_frequency_hz = 50.0
damping_ratio = 0.3
magnetic_lag_s = 0.0015
dead_band_a = 0.3
delay_s = 0.0005
predictor_gamma = [0.2, 0.2, 0.02, 0.02]
)";
constexpr std::string_view kTimeOptimal = R"(
[axes.valve_law.time_optimal]
trigger_m = 0.00017
margin_m = 1e-6
horizon_samples = 250
)";

// kModel with the line starting `key =` replaced by `line` (dropped when `line` is empty).
std::string model_with(std::string_view key, std::string_view line) { return config_test::with_line(kModel, key, line); }

TEST(ValveLawConfig, TheModelTableRunsTheModelPredictorOnTheIdentifiedValve) {
  const DaemonConfig c = parse_config(config("max_current_a = 2.5" + std::string(kModel)), "test.toml");
  const control::ValveLawParams& v = valve_of(c);
  const control::ValveModelPredictorParams& m = v.model_predictor;
  EXPECT_TRUE(m.enabled);
  EXPECT_EQ(m.valve, (control::IdentifiedValve{.gain_m_per_a = 0.0018238, .rest_position_m = -0.0025,
                                               .natural_frequency_hz = 50.0, .damping_ratio = 0.3,
                                               .magnetic_lag_s = 0.0015, .width_a = 0.3, .delay_s = 0.0005,
                                               .current_max_a = 2.5}));
  EXPECT_EQ(m.gamma, (std::array<double, 4>{0.2, 0.2, 0.02, 0.02}));
  EXPECT_FALSE(v.time_optimal.enabled);
  EXPECT_NE(dynamic_cast<const control::PiCascadeLaw&>(*c.axes[0].law).cascade().model_predictor(), nullptr);
  // Without the table the paper's predictor runs.
  const DaemonConfig paper = parse_config(config(""), "test.toml");
  EXPECT_FALSE(valve_of(paper).model_predictor.enabled);
  EXPECT_EQ(dynamic_cast<const control::PiCascadeLaw&>(*paper.axes[0].law).cascade().model_predictor(), nullptr);
}

TEST(ValveLawConfig, TheTimeOptimalTableRunsOnTheModelTablesValve) {
  const DaemonConfig c = parse_config(config(std::string(kModel) + std::string(kTimeOptimal)), "test.toml");
  const control::ValveTimeOptimalParams& o = valve_of(c).time_optimal;
  EXPECT_EQ(o, (control::ValveTimeOptimalParams{.enabled = true, .gain_m_per_a = 0.0018238, .rest_position_m = -0.0025,
                                                .natural_frequency_hz = 50.0, .damping_ratio = 0.3,
                                                .magnetic_lag_s = 0.0015, .width_a = 0.3, .delay_s = 0.0005,
                                                .trigger_m = 0.00017, .margin_m = 1e-6, .horizon_samples = 250}));
}

TEST(ValveLawConfig, CheckConfigDescribesThePredictorAndTheTimeOptimalMoves) {
  const std::string on = describe(parse_config(config(std::string(kModel) + std::string(kTimeOptimal)), "test.toml"));
  EXPECT_THAT(on, HasSubstr("predictor     the identified model's: g 0.0018238 m/A, X_min -0.0025 m, f0 50 Hz, zeta 0.3"));
  EXPECT_THAT(on, HasSubstr("tau_a 0.0015 s, w 0.3 A, delay 0.0005 s, gamma 0.2, 0.2, 0.02, 0.02"));
  EXPECT_THAT(on, HasSubstr("time-optimal  on: trigger 0.00017 m, margin 1e-06 m, horizon 250 samples"));
  const std::string off = describe(parse_config(config(""), "test.toml"));
  EXPECT_THAT(off, HasSubstr("predictor     the paper's (Canuto et al. (2014) eqs 15-16)"));
  EXPECT_THAT(off, HasSubstr("time-optimal  off"));
}

TEST(ValveLawConfig, EveryModelKeyIsRequired) {
  for (const char* key : {"gain_m_per_a", "rest_position_m", "natural_frequency_hz", "damping_ratio", "magnetic_lag_s",
                          "dead_band_a", "delay_s", "predictor_gamma"}) {
    // A missing key is reported at the table's header.
    expect_refused(model_with(key, ""), "[axes.valve_law.model]", std::string("model.") + key,
                   "required key is missing, expected");
  }
}

TEST(ValveLawConfig, ModelNumbersOutOfRangeAreRefused) {
  const struct {
    const char* key;
    const char* value;
    const char* expected;
  } cases[] = {
      {"gain_m_per_a", "0.0", "expected a finite number > 0, got 0"},
      {"gain_m_per_a", "nan", "expected a finite number > 0"},
      {"rest_position_m", "inf", "expected a finite number, got"},
      {"natural_frequency_hz", "-50.0", "expected a finite number > 0, got -50"},
      {"damping_ratio", "0.0", "expected a finite number > 0, got 0"},
      {"magnetic_lag_s", "-1e-3", "expected a finite number > 0"},
      {"dead_band_a", "-0.1", "expected a finite number in [0, 3], got -0.1"},
      {"dead_band_a", "3.5", "expected a finite number in [0, 3], got 3.5"},
      {"delay_s", "-1e-4", "expected a finite number >= 0"},
      // 17 base ticks: beyond the model's delay line of 16.
      {"delay_s", "0.0017", "expected a finite number in [0, 0.00165) s: at most 16 samples of the 0.0001 s base tick"},
      {"predictor_gamma", "[0.2, 0.2, 0.0, 0.02]", "expected an array of 4 numbers in (0, 1]"},
      {"predictor_gamma", "[0.2, 0.2, 0.02]", "expected an array of 4 numbers in (0, 1]"},
      {"predictor_gamma", "[0.2, 0.2, 0.02, 1.5]", "expected an array of 4 numbers in (0, 1]"},
  };
  for (const auto& c : cases) {
    const std::string line = std::string(c.key) + " = " + c.value;
    expect_refused(model_with(c.key, line), line, std::string("model.") + c.key, c.expected);
  }
  // 16 ticks is the longest delay the line holds.
  EXPECT_EQ(valve_of(parse_config(config(model_with("delay_s", "delay_s = 0.0016")), "test.toml"))
                .model_predictor.valve.delay_s,
            0.0016);
}

TEST(ValveLawConfig, UnknownModelAndTimeOptimalKeysAreRefused) {
  expect_refused(std::string(kModel) + "width_a = 0.3", "width_a", "model.width_a", "unknown key, expected one of:");
  expect_refused(std::string(kModel) + std::string(kTimeOptimal) + "delay_s = 0.0005", "delay_s = 0.0005\n[axes.limits]",
                 "time_optimal.delay_s", "unknown key, expected one of:");
}

TEST(ValveLawConfig, TimeOptimalWithoutTheModelIsRefused) {
  expect_refused(kTimeOptimal, "[axes.valve_law.time_optimal]", "time_optimal",
                 "expected no such table while [axes[0].valve_law.model] is absent (the moves run on the identified "
                 "model");
}

TEST(ValveLawConfig, ThePaperPredictorsEigenvaluesWithTheModelAreRefusedNotIgnored) {
  expect_refused("predictor_gamma = [0.4, 0.4, 0.04, 0.04]" + std::string(kModel), "predictor_gamma = [0.4",
                 "predictor_gamma", "expected no such key while [axes[0].valve_law.model] is present");
}

TEST(ValveLawConfig, TimeOptimalNumbersOutOfRangeAreRefused) {
  const struct {
    const char* key;
    const char* value;
    const char* expected;
  } cases[] = {
      {"trigger_m", "0.0", "expected a finite number > 0, got 0"},
      {"trigger_m", "nan", "expected a finite number > 0"},
      {"margin_m", "-1e-6", "expected a finite number >= 0"},
      {"horizon_samples", "0", "expected a finite number in [1, 2000], got 0"},
      {"horizon_samples", "2001", "expected a finite number in [1, 2000], got 2001"},
      {"horizon_samples", "2.5", "expected a whole number in [1, 2000] (samples; two predictions of it fit the 4000"},
  };
  for (const auto& c : cases) {
    std::string table(kTimeOptimal);
    const auto at = table.find(std::string("\n") + c.key + " = ");
    table.replace(at + 1, table.find('\n', at + 1) - at - 1, std::string(c.key) + " = " + c.value);
    const std::string line = std::string(c.key) + " = " + c.value;
    expect_refused(std::string(kModel) + table, line, std::string("time_optimal.") + c.key, c.expected);
  }
}

}  // namespace
}  // namespace hsa::daemon
