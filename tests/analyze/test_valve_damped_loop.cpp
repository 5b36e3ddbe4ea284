// The damped step of docs/valve-loop.md in lockstep on the simulated valve, the paper's and the
// variant of test_valve_loop_variant.cpp, each set from that valve's own identification: with
// K_v and K_a chosen on the identified valve (control/valve_feedback_design.hpp, never on the
// simulator), the triangle's peak residual falls below the model-predictor step's, with the delay
// and the band of Canuto et al. (2014)'s Table 3 kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tools/hsa_analyze/valve_experiments.hpp"
#include "valve_variant.hpp"

namespace {

using namespace hsa;

double band_db(const control::ValveLawParams& law, const sim::ProportionalValveParameters& valve) {
  double worst = 0.0;
  for (double hz : analyze::kValveSineFrequenciesHz)
    if (hz <= 100.0) worst = std::max(worst, std::abs(analyze::run_valve_sine(0.05, hz, law, valve).gain_db));
  return worst;
}

void expect_damped_better(const sim::ProportionalValveParameters& valve, bool is_variant) {
  const control::IdentifiedValve v = analyze::test::identified_from_record(valve, is_variant);
  const control::ValveLawParams damped = control::identified_valve_law(v, control::ValveLawStep::damped);
  const analyze::ValveTriangleMetrics d = analyze::run_valve_triangle(0.70, 10.0, damped, valve);
  const analyze::ValveTriangleMetrics mp =
      analyze::run_valve_triangle(0.70, 10.0, control::identified_valve_law(v, control::ValveLawStep::model_predictor), valve);
  const double band = band_db(damped, valve);
  std::printf("  damped: delay %.2f ms, residual max %.1f um rms %.1f um, within +-%.2f dB; model-predictor: max %.1f um\n",
              d.delay_s * 1e3, d.residual_max_m * 1e6, d.residual_rms_m * 1e6, band, mp.residual_max_m * 1e6);
  EXPECT_LT(d.residual_max_m, mp.residual_max_m);
  EXPECT_LT(d.residual_rms_m, mp.residual_rms_m);
  EXPECT_LE(d.delay_s, 3e-3);
  EXPECT_LE(band, 3.0);
}

TEST(ValveDampedLoop, LowersThePeakOnThePapersValve) { expect_damped_better({}, false); }

TEST(ValveDampedLoop, LowersThePeakOnTheVariantFromItsOwnIdentification) {
  expect_damped_better(analyze::test::variant_valve(), true);
}

}  // namespace
