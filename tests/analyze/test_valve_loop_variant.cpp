// The valve loop of docs/valve-loop.md on a valve nobody tuned for: the variant of
// test_identify_valve.cpp (a wider dead band, a softer spring, a lower current limit), identified
// on its own simulated record, the law set from that identification alone, and run on the variant
// itself. Canuto et al. (2014)'s requirements (Table 3) hold where they hold on the paper's valve;
// where the paper's valve misses one, the variant's figure is printed and pinned like the paper
// valve's in test_valve_loop.cpp (10 % on residuals, 5 % on the slew rate, 0.2 ms on the delay).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "control/identification/valve_fit.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"
#include "tools/hsa_analyze/valve_experiments.hpp"
#include "valve_variant.hpp"

namespace {

using namespace hsa;

sim::ProportionalValveParameters variant() { return analyze::test::variant_valve(); }

// Identified once from the record an operator makes on it (valve_variant.hpp).
control::IdentifiedValve identified_variant() {
  static const control::IdentifiedValve identified = analyze::test::identified_from_record(variant(), true);
  return identified;
}

double band_to_100hz(const control::ValveLawParams& law) {
  double worst = 0.0;
  for (double f : analyze::kValveSineFrequenciesHz)
    if (f <= 100.0) worst = std::max(worst, std::abs(analyze::run_valve_sine(0.05, f, law, variant()).gain_db));
  return worst;
}

TEST(ValveLoopVariant, TheLawsParametersAreTheVariantsNotThePapers) {
  const sim::ProportionalValveParameters v = variant();
  const double k = v.moving_mass_kg * std::pow(2.0 * std::numbers::pi * v.natural_frequency_hz, 2);
  const double g = v.force_constant_n_per_a / k;  // m/A
  const control::ValveLawParams paper = control::simulated_proportional_valve_law();
  for (control::ValveLawStep step : {control::ValveLawStep::spring_inverse, control::ValveLawStep::feedforward,
                                     control::ValveLawStep::model_inverse}) {
    const control::ValveLawParams law = control::identified_valve_law(identified_variant(), step);
    std::printf("  I_max %.3f A, K_r %.1f A/m, I0 %.4f A, dither %.2f A\n", law.max_current_a,
                law.feedforward_a_per_m, law.bias_current_a, law.dither_amplitude_a);
    // The variant's 2.5 A, not the paper's 3 A.
    EXPECT_NEAR(law.max_current_a, v.current_max_a, 0.10 * v.current_max_a);
    EXPECT_LT(law.max_current_a, paper.max_current_a - 0.25);
    // K_r = K/K_f of the softer spring: 351 A/m against the paper's 548.
    EXPECT_NEAR(law.feedforward_a_per_m, 1.0 / g, 0.10 / g);
    EXPECT_LT(law.feedforward_a_per_m, 0.8 * paper.feedforward_a_per_m);
    // I0 = −X_min/g + w/2 = 0.88 + 0.25 A, against the paper's 1.52 A.
    const double bias = -v.stroke_min_m / g + 0.5 * v.hysteresis_width_a;
    EXPECT_NEAR(law.bias_current_a, bias, 0.10 * bias);
    EXPECT_LT(law.bias_current_a, paper.bias_current_a - 0.2);
    // The dither is the identified dead band's width: 0.5 A, against the paper valve's 0.3 A.
    EXPECT_NEAR(law.dither_amplitude_a, v.hysteresis_width_a, 0.10 * v.hysteresis_width_a);
    EXPECT_GT(law.dither_amplitude_a, paper.dither_amplitude_a + 0.1);
    EXPECT_LE(law.dither_amplitude_a, 0.5 * law.max_current_a);
  }
  // The model's terms: a1/g from the variant's 40 Hz mode (a1 = 2ζ/ω0 + τa + δ). The identified δ
  // also holds the LVDT's lag (about 0.2 ms, 5 % of a1) that the valve's own parameters do not.
  const control::ValveLawParams law = control::identified_valve_law(identified_variant(),
                                                                    control::ValveLawStep::feedforward);
  const double w0 = 2.0 * std::numbers::pi * v.natural_frequency_hz;
  const double a1 = 2.0 * v.damping_ratio / w0 + v.magnetic_lag_s + v.current_delay_s;
  std::printf("  K_rv %.3f A/(m/s), from the variant's a1/g %.3f\n", law.reference_velocity_a_per_m_s, a1 / g);
  EXPECT_NEAR(law.reference_velocity_a_per_m_s, a1 / g, 0.15 * a1 / g);
}

TEST(ValveLoopVariant, TheSlewBoundOfThePhysicsLiesAboveTheRequirement) {
  const analyze::ValveSlewBound b = analyze::valve_slew_bound(0.50, variant());
  // docs/valve-loop.md: 2.80 ms up at 2.5 A, 3.13 ms down, 0.34 m/s; the paper valve's is 0.38.
  std::printf("  10-90 %% %.2f ms up, %.2f ms down: %.3f m/s\n", b.rise_up_s * 1e3, b.rise_down_s * 1e3,
              b.slew_rate_m_s);
  EXPECT_NEAR(b.rise_up_s, 2.80e-3, 0.2e-3);
  EXPECT_NEAR(b.rise_down_s, 3.13e-3, 0.2e-3);
  EXPECT_GT(b.slew_rate_m_s, 0.25);
  EXPECT_LT(b.slew_rate_m_s, analyze::valve_slew_bound(0.50).slew_rate_m_s);
}

TEST(ValveLoopVariant, ModelInverseIdentifiedOnTheVariantHoldsWhatItHoldsOnThePapersValve) {
  const control::ValveLawParams law =
      control::identified_valve_law(identified_variant(), control::ValveLawStep::model_inverse);
  const analyze::ValveTriangleMetrics tri = analyze::run_valve_triangle(0.70, 10.0, law, variant());
  const analyze::ValveSquareMetrics sq = analyze::run_valve_square(0.50, 10.0, law, variant());
  const double band = band_to_100hz(law);
  std::printf("  delay %.2f ms, residual max %.1f um rms %.1f um, slew %.3f m/s, within +-%.2f dB\n", tri.delay_s * 1e3,
              tri.residual_max_m * 1e6, tri.residual_rms_m * 1e6, sq.slew_rate_m_s, band);
  // Met on the paper's valve, met here: delay, rms residual, band.
  EXPECT_LE(tri.delay_s, 5e-3);
  EXPECT_LE(tri.residual_rms_m, 10e-6);
  EXPECT_LE(band, 3.0);
  EXPECT_LE(sq.slew_rate_m_s, analyze::valve_slew_bound(0.50, variant()).slew_rate_m_s);
  // Missed on the paper's valve (34.3 µm, 0.195 m/s), missed here too: pinned where
  // docs/valve-loop.md has them (1.54 ms, 36.4 µm, 9.4 µm, 0.196 m/s).
  std::printf("  misses, as on the paper's valve: residual max %.1f um > 10 um, slew %.3f m/s < 0.25 m/s\n",
              tri.residual_max_m * 1e6, sq.slew_rate_m_s);
  EXPECT_LE(tri.delay_s, 1.54e-3 + 0.2e-3);
  EXPECT_LE(tri.residual_max_m, 36.4e-6 * 1.10);
  EXPECT_LE(tri.residual_rms_m, 9.4e-6 * 1.10);
  EXPECT_GE(sq.slew_rate_m_s, 0.196 * 0.95);
}

// What the identification buys: the preset, tuned on the paper's valve, leaves the band on the
// variant (its static inverse, bias and dither are the paper valve's).
TEST(ValveLoopVariant, ThePresetTunedOnThePapersValveLeavesTheBandOnTheVariant) {
  const double band = band_to_100hz(control::simulated_proportional_valve_law());
  std::printf("  preset on the variant: within +-%.2f dB\n", band);
  EXPECT_GT(band, 3.0);
}

}  // namespace
