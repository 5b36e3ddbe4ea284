// The valve law's model-inverse feed-forward of the reference and its repetitive rejection
// (control/valve_law.hpp), and the law set from an identified valve (identified_valve_law).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "control/valve_law.hpp"

namespace hsa::control {
namespace {

// Only the terms under test: a bias and the spring inverse, no error terms unless a test adds them.
ValveLawParams bare() {
  ValveLawParams p;
  p.bias_current_a = 1.5;
  p.max_current_a = 3.0;
  p.feedforward_a_per_m = 500.0;
  p.velocity_a_per_m_s = 4.0;
  return p;
}

TEST(ValveFeedforward, OffByDefaultAndAfterAReset) {
  ValveLaw law(bare());
  EXPECT_EQ(law.update(1e-4, {.position_m = 1e-4}), 1.5 + 500.0 * 1e-4);
}

TEST(ValveFeedforward, ARampGetsItsSlopeTimesTheVelocityGainOnceTheFilterSettles) {
  ValveLawParams p = bare();
  p.reference_filter_hz = 200.0;
  p.reference_velocity_a_per_m_s = 6.0;
  p.reference_acceleration_a_per_m_s2 = 0.01;
  ValveLaw law(p);
  const double slope = 0.05;  // m/s
  double out = 0.0, r = 0.0;
  // 50 ms = 63 filter time constants 1/ω_r: the filter's ṙ_f is on the slope, r̈_f near zero.
  for (int k = 0; k < 500; ++k) {
    r = slope * k * p.period_s;
    out = law.update(r, {.position_m = r, .velocity_m_s = slope});
  }
  // The spool on its reference at the reference's speed: the measured-state damping −K_v·v is
  // cancelled by nothing but K_rv·ṙ, so the output is I0 + K_r·r + (K_rv − K_v)·ṙ.
  EXPECT_NEAR(out, 1.5 + 500.0 * r + (6.0 - 4.0) * slope, 1e-6);
}

TEST(ValveFeedforward, AStepGivesAPulseTheLimitClipsThenNothing) {
  ValveLawParams p = bare();
  p.reference_filter_hz = 250.0;
  p.reference_velocity_a_per_m_s = 9.0;
  p.reference_acceleration_a_per_m_s2 = 0.02;
  ValveLaw law(p);
  EXPECT_EQ(law.update(0.0, {}), 1.5);  // the filter starts on the reference: no pulse
  const double first = law.update(1e-3, {.position_m = 0.0});
  EXPECT_EQ(first, 3.0) << "the step's acceleration pulse saturates the current";
  double out = 0.0;
  for (int k = 0; k < 1000; ++k) out = law.update(1e-3, {.position_m = 1e-3});
  EXPECT_NEAR(out, 1.5 + 500.0 * 1e-3, 1e-6) << "100 ms later the filter is at rest on the step";
}

TEST(ValveFeedforward, TrackingTheFilteredReferenceTakesTheErrorFromIt) {
  ValveLawParams p = bare();
  p.velocity_a_per_m_s = 0.0;
  p.proportional_a_per_m = 1000.0;
  p.reference_filter_hz = 200.0;
  p.track_filtered_reference = true;
  ValveLaw law(p);
  EXPECT_EQ(law.update(0.0, {}), 1.5);
  // A step of 1 mm: in the first sample the filter's chain moves r_f by T·T·T·ω_r³·Δ only (jerk,
  // then acceleration, velocity and position each one step), so the error is that of r_f.
  const double out = law.update(1e-3, {});
  EXPECT_LT(out, 1.5 + 0.01);
  const double wt = 2.0 * std::numbers::pi * 200.0 * 1e-4;
  EXPECT_NEAR(law.error(), wt * wt * wt * 1e-3, 1e-12);
  double later = 0.0;
  for (int k = 0; k < 2000; ++k) later = law.update(1e-3, {.position_m = 0.0});
  EXPECT_NEAR(law.error(), 1e-3, 1e-9) << "200 ms later r_f is on the step";
  EXPECT_NEAR(later, 1.5 + 500.0 * 1e-3 + 1000.0 * 1e-3, 1e-6);
}

TEST(ValveFeedforward, DirectionCompensationFollowsTheSignOfTheReferenceSpeed) {
  ValveLawParams p = bare();
  p.velocity_a_per_m_s = 0.0;
  p.reference_filter_hz = 200.0;
  p.direction_compensation_a = 0.15;
  p.direction_velocity_m_s = 1e-3;
  for (double sign : {1.0, -1.0}) {
    ValveLaw law(p);
    double out = 0.0, r = 0.0;
    for (int k = 0; k < 500; ++k) {
      r = sign * 0.05 * k * p.period_s;
      out = law.update(r, {.position_m = r});
    }
    EXPECT_NEAR(out, 1.5 + 500.0 * r + sign * 0.15 * std::tanh(0.05 / 1e-3), 1e-6) << sign;
  }
}

TEST(ValveRepetitive, ActsOnePeriodLaterAndBuildsUpOnARepeatedError) {
  ValveLawParams p = bare();
  p.velocity_a_per_m_s = 0.0;
  p.repetitive_period_samples = 20;
  p.repetitive_gain = 100.0;
  p.repetitive_filter_hz = 400.0;
  ValveLaw law(p);
  const double e = 1e-4;  // a constant error: the reference at e, the spool at 0
  const double plain = 1.5 + 500.0 * e;
  for (int k = 0; k < 20; ++k) EXPECT_EQ(law.update(e, {}), plain) << "sample " << k;
  const double one_period = law.update(e, {}) - plain;
  EXPECT_GT(one_period, 0.0);
  EXPECT_LT(one_period, 100.0 * e);  // the low-pass Q lets part of k_rep·e through in one sample
  double later = 0.0;
  for (int k = 0; k < 60; ++k) later = law.update(e, {}) - plain;
  EXPECT_GT(later, 100.0 * e) << "three periods on, the repeated error has accumulated";
  law.reset();
  EXPECT_EQ(law.update(e, {}), plain) << "reset empties the repetitive memory";
}

TEST(ValveFeedforward, RejectsSettingsOutOfRange) {
  const auto rejects = [](auto edit) {
    ValveLawParams p = bare();
    edit(p);
    EXPECT_THROW(ValveLaw{p}, std::invalid_argument);
  };
  rejects([](ValveLawParams& p) { p.reference_filter_hz = -1.0; });
  rejects([](ValveLawParams& p) { p.reference_filter_hz = 600.0; });  // above 0.05/T at 10 kHz
  rejects([](ValveLawParams& p) { p.reference_velocity_a_per_m_s = NAN; });
  rejects([](ValveLawParams& p) { p.direction_velocity_m_s = 0.0; });
  rejects([](ValveLawParams& p) { p.repetitive_period_samples = -1; });
  rejects([](ValveLawParams& p) {
    p.repetitive_period_samples = 10;
    p.repetitive_filter_hz = 100.0;
    p.repetitive_lead_samples = 10;
  });
  rejects([](ValveLawParams& p) { p.repetitive_period_samples = 10; });  // no Q filter
}

IdentifiedValve paper_like() {
  return {.gain_m_per_a = 2.0e-3, .rest_position_m = -2.4e-3, .natural_frequency_hz = 45.0, .damping_ratio = 0.35,
          .magnetic_lag_s = 1.2e-3, .width_a = 0.25, .delay_s = 0.5e-3, .current_max_a = 2.8};
}

TEST(IdentifiedValveLaw, EachStepTakesWhatTheModelFixes) {
  const IdentifiedValve v = paper_like();
  const ValveLawParams preset = simulated_proportional_valve_law();
  const ValveLawParams s = identified_valve_law(v, ValveLawStep::spring_inverse);
  EXPECT_NEAR(s.feedforward_a_per_m, 1.0 / 2.0e-3, 1e-9);
  EXPECT_NEAR(s.bias_current_a, 2.4e-3 / 2.0e-3 + 0.125, 1e-12);  // (0 − X_min)/g + w/2
  EXPECT_EQ(s.max_current_a, 2.8);
  EXPECT_EQ(s.dither_amplitude_a, 0.25);  // the identified w, not the preset's 0.3 A
  EXPECT_EQ(s.dither_frequency_hz, preset.dither_frequency_hz);
  EXPECT_EQ(s.proportional_a_per_m, preset.proportional_a_per_m);
  EXPECT_EQ(s.reference_filter_hz, 0.0);

  const ValveLawParams f = identified_valve_law(v, ValveLawStep::feedforward);
  const double w0 = 2.0 * std::numbers::pi * 45.0;
  EXPECT_NEAR(f.reference_velocity_a_per_m_s, (2.0 * 0.35 / w0 + 1.2e-3 + 0.5e-3) / 2.0e-3, 1e-9);  // a1/g
  EXPECT_EQ(f.reference_acceleration_a_per_m_s2, 0.0);
  EXPECT_GT(f.reference_filter_hz, 0.0);
  EXPECT_FALSE(f.track_filtered_reference);
  EXPECT_EQ(f.repetitive_period_samples, 0);
  EXPECT_NO_THROW(ValveLaw{f});

  const ValveLawParams m = identified_valve_law(v, ValveLawStep::model_inverse);
  EXPECT_NEAR(m.reference_velocity_a_per_m_s, (2.0 * 0.35 / w0 + 1.2e-3 + 0.5e-3) / 2.0e-3 + preset.velocity_a_per_m_s,
              1e-9);
  EXPECT_NEAR(m.reference_acceleration_a_per_m_s2,
              (1.0 + 2.0 * 0.35 * w0 * 1.2e-3) / (w0 * w0) / 2.0e-3 + preset.acceleration_a_per_m_s2, 1e-12);
  EXPECT_NEAR(m.reference_jerk_a_per_m_s3, 1.2e-3 / (w0 * w0) / 2.0e-3, 1e-15);
  EXPECT_TRUE(m.track_filtered_reference);
  EXPECT_NO_THROW(ValveLaw{m});

  const ValveLawParams r = identified_valve_law(v, ValveLawStep::repetitive, 0.1);
  EXPECT_EQ(r.repetitive_period_samples, 1000);
  EXPECT_EQ(r.reference_velocity_a_per_m_s, m.reference_velocity_a_per_m_s);
  EXPECT_TRUE(r.track_filtered_reference);
  EXPECT_NO_THROW(ValveLaw{r});
}

// The dither follows the identified band up to ValveLaw's I_max/2, and is off for a valve without one.
TEST(IdentifiedValveLaw, DitherIsTheIdentifiedDeadBand) {
  IdentifiedValve v = paper_like();
  v.width_a = 1.6;
  EXPECT_EQ(identified_valve_law(v, ValveLawStep::spring_inverse).dither_amplitude_a, 1.4);
  EXPECT_NO_THROW(ValveLaw{identified_valve_law(v, ValveLawStep::spring_inverse)});
  v.width_a = 0.0;
  EXPECT_EQ(identified_valve_law(v, ValveLawStep::model_inverse).dither_amplitude_a, 0.0);
  EXPECT_NO_THROW(ValveLaw{identified_valve_law(v, ValveLawStep::model_inverse)});
}

TEST(IdentifiedValveLaw, RefusesANonPhysicalValveOrAMissingPeriod) {
  for (auto edit : {+[](IdentifiedValve& v) { v.gain_m_per_a = 0.0; }, +[](IdentifiedValve& v) { v.damping_ratio = -0.1; },
                    +[](IdentifiedValve& v) { v.magnetic_lag_s = NAN; }, +[](IdentifiedValve& v) { v.width_a = -0.1; },
                    +[](IdentifiedValve& v) { v.current_max_a = 0.0; }}) {
    IdentifiedValve v = paper_like();
    edit(v);
    EXPECT_THROW((void)identified_valve_law(v, ValveLawStep::spring_inverse), std::invalid_argument);
  }
  EXPECT_THROW((void)identified_valve_law(paper_like(), ValveLawStep::repetitive), std::invalid_argument);
  EXPECT_THROW((void)identified_valve_law(paper_like(), ValveLawStep::repetitive, 0.10005), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
