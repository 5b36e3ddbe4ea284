// The valve loop of docs/valve-loop.md in lockstep on the simulated rig: the law set from the valve
// identified on a simulated record (valve_excitation + fit_valve), never from the paper's tables,
// against Canuto et al. (2014)'s triangle, square and sine experiments. Tolerances are fixed rules
// (10 % on residuals, 5 % on the slew rate, 0.2 ms on the delay, the paper's ±3 dB hard) around
// the figures docs/valve-loop.md reports, so a change that loses what a step won fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "control/identification/valve_fit.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"
#include "tools/hsa_analyze/valve_experiments.hpp"

namespace {

using namespace hsa;

control::IdentifiedValve identified() {
  return control::identification::identified_valve(
      control::identification::fit_valve(analyze::run_valve_excitation(analyze::ValveExcitation{})));
}

double band_to_100hz(const control::ValveLawParams& law) {
  double worst = 0.0;
  for (double f : analyze::kValveSineFrequenciesHz)
    if (f <= 100.0) worst = std::max(worst, std::abs(analyze::run_valve_sine(0.05, f, law).gain_db));
  return worst;
}

TEST(ValveLoop, TheSlewBoundOfThePhysicsLiesAboveTheRequirement) {
  const analyze::ValveSlewBound b = analyze::valve_slew_bound(0.50);
  // docs/valve-loop.md: about 2.6 ms each way, 0.38 m/s.
  EXPECT_NEAR(b.rise_up_s, 2.63e-3, 0.2e-3);
  EXPECT_NEAR(b.rise_down_s, 2.60e-3, 0.2e-3);
  EXPECT_GT(b.slew_rate_m_s, 0.25);
}

struct Pinned {
  double delay_s, residual_max_m, residual_rms_m, slew_m_s;
};

void expect_pinned(control::ValveLawStep step, const Pinned& pin) {
  const control::ValveLawParams law = control::identified_valve_law(identified(), step);
  const analyze::ValveTriangleMetrics tri = analyze::run_valve_triangle(0.70, 10.0, law);
  const analyze::ValveSquareMetrics sq = analyze::run_valve_square(0.50, 10.0, law);
  const double band = band_to_100hz(law);
  std::printf("  delay %.2f ms, residual max %.1f um rms %.1f um, slew %.3f m/s, within +-%.2f dB\n", tri.delay_s * 1e3,
              tri.residual_max_m * 1e6, tri.residual_rms_m * 1e6, sq.slew_rate_m_s, band);
  EXPECT_LE(tri.delay_s, pin.delay_s + 0.2e-3);
  EXPECT_LE(tri.residual_max_m, pin.residual_max_m * 1.10);
  EXPECT_LE(tri.residual_rms_m, pin.residual_rms_m * 1.10);
  EXPECT_GE(sq.slew_rate_m_s, pin.slew_m_s * 0.95);
  EXPECT_LE(sq.slew_rate_m_s, analyze::valve_slew_bound(0.50).slew_rate_m_s);
  EXPECT_LE(band, 3.0);
}

TEST(ValveLoop, FeedforwardFromTheIdentifiedValveWinsSlewRate) {
  expect_pinned(control::ValveLawStep::feedforward, {2.27e-3, 73.5e-6, 23.3e-6, 0.246});
  // Faster than the preset's 0.205 m/s by more than the tolerance.
  EXPECT_GT(analyze::run_valve_square(0.50, 10.0,
                                      control::identified_valve_law(identified(), control::ValveLawStep::feedforward))
                .slew_rate_m_s,
            analyze::run_valve_square(0.50, 10.0).slew_rate_m_s * 1.10);
}

TEST(ValveLoop, ModelInverseFromTheIdentifiedValveWinsResidualAndDelay) {
  expect_pinned(control::ValveLawStep::model_inverse, {1.54e-3, 34.3e-6, 8.2e-6, 0.195});
  // The rms residual meets the 10 µm requirement, the preset's (10.8 µm) does not.
  const analyze::ValveTriangleMetrics tri = analyze::run_valve_triangle(
      0.70, 10.0, control::identified_valve_law(identified(), control::ValveLawStep::model_inverse));
  EXPECT_LE(tri.residual_rms_m, 10e-6);
  EXPECT_GT(analyze::run_valve_triangle(0.70, 10.0).residual_rms_m, 10e-6);
}

// The rig's seed draws its noise again and nothing else: the same seed repeats a run to the bit,
// another gives another peak (a maximum over noisy samples) around the same delay and rms.
TEST(ValveLoop, AnotherRigSeedIsAnotherDrawOfTheSameExperiment) {
  const control::ValveLawParams law = control::identified_valve_law(identified(), control::ValveLawStep::model_inverse);
  const auto run = [&](std::uint64_t seed) { return analyze::run_valve_triangle(0.70, 10.0, law, {}, nullptr, seed); };
  const analyze::ValveTriangleMetrics one = run(1), again = run(1), two = run(2);
  EXPECT_EQ(one.residual_max_m, again.residual_max_m);
  EXPECT_EQ(one.nonrepeating_rms_m, again.nonrepeating_rms_m);
  EXPECT_NE(one.residual_max_m, two.residual_max_m);
  EXPECT_NE(one.nonrepeating_rms_m, two.nonrepeating_rms_m);
  EXPECT_NEAR(two.delay_s, one.delay_s, 0.05e-3);
  EXPECT_NEAR(two.residual_rms_m, one.residual_rms_m, 0.1 * one.residual_rms_m);
}

}  // namespace
