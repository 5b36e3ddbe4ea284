// The valve law's damping chosen on the identified valve (control/valve_feedback_design.hpp): on
// a paper-like identified valve it picks more damping than the preset's and lowers the design
// model's peak residual; the choice is what the damped step runs; the model-inverse feed-forward
// is kept; bad settings are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "control/valve_feedback_design.hpp"
#include "control/valve_law.hpp"

namespace hsa::control {
namespace {

// An identified valve as identified_valve() gives it for the paper's valve (round figures).
IdentifiedValve paper_like() {
  return {.gain_m_per_a = 1.0 / 548.3, .rest_position_m = -2.5e-3, .natural_frequency_hz = 50.0,
          .damping_ratio = 0.3, .magnetic_lag_s = 1.5e-3, .width_a = 0.3, .delay_s = 0.5e-3, .current_max_a = 3.0};
}

TEST(ValveFeedbackDesign, PicksMoreDampingThanThePresetAndLowersThePeakOnTheDesignModel) {
  const IdentifiedValve v = paper_like();
  const ValveLawParams base = identified_valve_law(v, ValveLawStep::model_predictor);
  const ValveFeedbackDesign d = design_valve_feedback(v, base);
  std::printf("  K_v x %.1f, K_a x %.1f: peak %.1f um on the identified model (preset factors %.1f um)\n",
              d.velocity_factor, d.acceleration_factor, d.peak_m * 1e6, d.preset_peak_m * 1e6);
  EXPECT_GT(d.velocity_factor * d.acceleration_factor, 1.0);
  EXPECT_LT(d.peak_m, d.preset_peak_m);
  EXPECT_GT(d.peak_m, 0.0);
  // Deterministic: the same noise sequence, the same choice.
  const ValveFeedbackDesign again = design_valve_feedback(v, base);
  EXPECT_EQ(again.velocity_factor, d.velocity_factor);
  EXPECT_EQ(again.acceleration_factor, d.acceleration_factor);
  EXPECT_EQ(again.peak_m, d.peak_m);
  // The damped step runs that choice.
  const ValveLawParams damped = identified_valve_law(v, ValveLawStep::damped);
  EXPECT_DOUBLE_EQ(damped.velocity_a_per_m_s, d.velocity_factor * base.velocity_a_per_m_s);
  EXPECT_DOUBLE_EQ(damped.acceleration_a_per_m_s2, d.acceleration_factor * base.acceleration_a_per_m_s2);
}

TEST(ValveFeedbackDesign, TheModelInverseFeedforwardStaysTheIdentifiedOne) {
  const ValveLawParams base = identified_valve_law(paper_like(), ValveLawStep::model_predictor);
  const ValveLawParams scaled = with_feedback_factors(base, 2.0, 1.5);
  EXPECT_DOUBLE_EQ(scaled.velocity_a_per_m_s, 2.0 * base.velocity_a_per_m_s);
  EXPECT_DOUBLE_EQ(scaled.acceleration_a_per_m_s2, 1.5 * base.acceleration_a_per_m_s2);
  // K_rv − K_v = a1/g and K_ra − K_a = a2/g: the valve's inverse, untouched.
  EXPECT_NEAR(scaled.reference_velocity_a_per_m_s - scaled.velocity_a_per_m_s,
              base.reference_velocity_a_per_m_s - base.velocity_a_per_m_s, 1e-12);
  EXPECT_NEAR(scaled.reference_acceleration_a_per_m_s2 - scaled.acceleration_a_per_m_s2,
              base.reference_acceleration_a_per_m_s2 - base.acceleration_a_per_m_s2, 1e-15);
}

TEST(ValveFeedbackDesign, RefusesSettingsItCannotUse) {
  const IdentifiedValve v = paper_like();
  const ValveLawParams base = identified_valve_law(v, ValveLawStep::model_predictor);
  ValveFeedbackDesignSettings s;
  s.velocity_factors = {};
  EXPECT_THROW(design_valve_feedback(v, base, s), std::invalid_argument);
  s = {};
  s.acceleration_factors = {1.0, -1.0};
  EXPECT_THROW(design_valve_feedback(v, base, s), std::invalid_argument);
  s = {};
  s.lvdt_noise_m = NAN;
  EXPECT_THROW(design_valve_feedback(v, base, s), std::invalid_argument);
  EXPECT_THROW(design_valve_feedback(v, identified_valve_law(v, ValveLawStep::model_inverse)), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
