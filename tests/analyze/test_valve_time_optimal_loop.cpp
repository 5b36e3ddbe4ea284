// The time-optimal step of docs/valve-loop.md in lockstep on the simulated valve, the paper's and
// the variant of test_valve_loop_variant.cpp, each law set from that valve's own identification:
// the square's jump is driven at full current and braked on the identified model's switching
// curve, so the slew rate meets Canuto et al. (2014)'s 0.25 m/s (Table 3) inside the physics'
// bound, while the triangle and the sines, whose reference the filter follows, never trigger a
// move and keep the figures of the law underneath (damped: the model-inverse law behind the
// predictor driven by the identified model, its damping chosen on the identified valve).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "control/identification/valve_fit.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"
#include "tools/hsa_analyze/valve_experiments.hpp"
#include "valve_variant.hpp"

namespace {

using namespace hsa;

sim::ProportionalValveParameters variant() { return analyze::test::variant_valve(); }

control::IdentifiedValve identified(const sim::ProportionalValveParameters& valve, bool is_variant) {
  return analyze::test::identified_from_record(valve, is_variant);
}

struct Figures {
  analyze::ValveTriangleMetrics tri;
  analyze::ValveSquareMetrics sq;
  std::vector<analyze::ValveSineMetrics> sweep;
  double band_db = 0.0;  // largest |gain| to 100 Hz
};

Figures figures(const control::ValveLawParams& law, const sim::ProportionalValveParameters& valve) {
  Figures f;
  f.tri = analyze::run_valve_triangle(0.70, 10.0, law, valve);
  f.sq = analyze::run_valve_square(0.50, 10.0, law, valve);
  for (double hz : analyze::kValveSineFrequenciesHz) {
    f.sweep.push_back(analyze::run_valve_sine(0.05, hz, law, valve));
    if (hz <= 100.0) f.band_db = std::max(f.band_db, std::abs(f.sweep.back().gain_db));
  }
  return f;
}

// The triangle and the sines never trigger a move: their figures are the damped law's.
// Returns the square's figures of both laws.
std::pair<analyze::ValveSquareMetrics, analyze::ValveSquareMetrics> expect_tracking_kept(
    const sim::ProportionalValveParameters& valve, bool is_variant) {
  const control::IdentifiedValve v = identified(valve, is_variant);
  const Figures to = figures(control::identified_valve_law(v, control::ValveLawStep::time_optimal), valve);
  const Figures mi = figures(control::identified_valve_law(v, control::ValveLawStep::damped), valve);
  const double bound = analyze::valve_slew_bound(0.50, valve).slew_rate_m_s;
  std::printf("  time-optimal: delay %.2f ms, residual max %.1f um rms %.1f um, slew %.3f m/s (bound %.3f), "
              "overshoot %.1f %%, settled %.1f um, within +-%.2f dB, -3 dB at %.0f Hz\n",
              to.tri.delay_s * 1e3, to.tri.residual_max_m * 1e6, to.tri.residual_rms_m * 1e6, to.sq.slew_rate_m_s,
              bound, to.sq.overshoot_pct, to.sq.settled_error_m * 1e6, to.band_db,
              analyze::minus_3db_frequency_hz(to.sweep));
  std::printf("  damped: slew %.3f m/s, overshoot %.1f %%\n", mi.sq.slew_rate_m_s, mi.sq.overshoot_pct);
  EXPECT_LE(to.sq.slew_rate_m_s, bound);
  // The delay and the band of the requirement.
  EXPECT_LE(to.tri.delay_s, 5e-3);
  EXPECT_LE(to.band_db, 3.0);
  // The triangle and the sines are the damped law's, not worse in any figure.
  EXPECT_LE(to.tri.delay_s, mi.tri.delay_s);
  EXPECT_LE(to.tri.residual_max_m, mi.tri.residual_max_m);
  EXPECT_LE(to.tri.residual_rms_m, mi.tri.residual_rms_m);
  EXPECT_LE(to.band_db, mi.band_db);
  EXPECT_GE(analyze::minus_3db_frequency_hz(to.sweep), analyze::minus_3db_frequency_hz(mi.sweep));
  return {to.sq, mi.sq};
}

TEST(ValveTimeOptimalLoop, MeetsTheSlewRateOnThePapersValveAndKeepsTheTracking) {
  const auto [to, mi] = expect_tracking_kept({}, false);
  // Canuto et al. (2014)'s slew rate (docs/valve-loop.md: 0.302 m/s against the damped law's 0.092).
  EXPECT_GE(to.slew_rate_m_s, 0.25);
  // Braked onto the target: the square settles as the damped law's does, within 10 % of the
  // step's overshoot (0.9 % measured).
  EXPECT_LE(to.overshoot_pct, 10.0);
  EXPECT_LE(to.settled_error_m, std::max(2.0 * mi.settled_error_m, 10e-6));
}

// On the variant (a wider dead band, a softer spring, a lower I_max), set from its own
// identification, the slew rate is met too (docs/valve-loop.md: 0.268 m/s, bound 0.337).
TEST(ValveTimeOptimalLoop, MeetsTheSlewRateOnTheVariantFromItsOwnIdentification) {
  const auto [to, mi] = expect_tracking_kept(variant(), true);
  EXPECT_GE(to.slew_rate_m_s, 0.25);
  EXPECT_GT(to.slew_rate_m_s, mi.slew_rate_m_s);
  EXPECT_LE(to.overshoot_pct, 10.0);
  EXPECT_LE(to.settled_error_m, std::max(2.0 * mi.settled_error_m, 10e-6));
}

}  // namespace
