// The predictive valve law (control/valve_predictive.hpp) and its design
// (control/valve_predictive_design.hpp), on their own: the law run on the very model its matrices
// were built from, so that whatever it misses is the law's and not the plant's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "control/valve_predictive_design.hpp"
#include "tests/support/counting_allocator.hpp"

namespace {

using namespace hsa::control;

constexpr double kT = 1e-4;
constexpr double kDitherHz = 2500.0;

// The paper's valve as the fit sees it, here without the dead band and the friction so that the
// law's model (the play at its mean, the friction on the target) is the plant exactly.
ValvePredictiveValve linear_valve() {
  ValvePredictiveValve v;
  v.model.width_a = 0.0;
  v.model.friction_band_m = 0.0;
  v.regulator_delay_s = 2e-4;
  v.current_max_a = 3.0;
  return v;
}

// The law's own discrete model as the plant: z ← A·z + B·I + F·φ, with φ = 0 (no friction).
struct OwnModel {
  explicit OwnModel(const ValvePredictiveParams& p, double position_m)
      : p(p), n(kValvePredictiveFixedStates + p.delay_samples), z(static_cast<std::size_t>(n), 0.0) {
    const double force = (position_m - p.rest_position_m) / p.gain_m_per_a;
    z[kForce] = force;
    z[kPosition] = z[kReading] = position_m;
    z[kOne] = 1.0;
    for (int j = kValvePredictiveFixedStates; j < n; ++j) z[static_cast<std::size_t>(j)] = force + p.mean_play_a;
  }
  [[nodiscard]] double reading() const { return z[kReading]; }
  void step(double current_a) {
    for (int r = 0; r < n; ++r) {
      double s = p.input[static_cast<std::size_t>(r)] * current_a;
      for (int c = 0; c < n; ++c) s += p.transition[static_cast<std::size_t>(r * n + c)] * z[static_cast<std::size_t>(c)];
      next[static_cast<std::size_t>(r)] = s;
    }
    z = next;
  }
  const ValvePredictiveParams& p;
  int n;
  std::vector<double> z;
  std::vector<double> next = z;  // sized once: the test counts the law's allocations
};

ValvePredictiveSettings settings(int preview) {
  ValvePredictiveSettings s;
  s.preview_samples = preview;
  s.dither_fraction = 0.0;
  s.rate_weight_m2_per_a2 = 5e-11;
  return s;
}

TEST(ValvePredictiveDesign, RefusesWhatItCannotBuild) {
  ValvePredictiveValve v = linear_valve();
  EXPECT_NO_THROW((void)valve_predictive_params(v, kT, kDitherHz, settings(8)));
  ValvePredictiveValve no_gain = v;
  no_gain.model.gain_m_per_a = 0.0;
  EXPECT_THROW((void)valve_predictive_params(no_gain, kT, kDitherHz, settings(8)), std::invalid_argument);
  ValvePredictiveValve short_delay = v;  // τ + δ of one period leaves no command in the delay line
  short_delay.regulator_delay_s = 1e-4;
  short_delay.model.delay_s = 0.0;
  EXPECT_THROW((void)valve_predictive_params(short_delay, kT, kDitherHz, settings(8)), std::invalid_argument);
  ValvePredictiveValve wide = v;  // a dither of 1.6 A on both sides of a 3 A range
  wide.model.width_a = 1.6;
  ValvePredictiveSettings dithered = settings(8);
  dithered.dither_fraction = 1.0;
  EXPECT_THROW((void)valve_predictive_params(wide, kT, kDitherHz, dithered), std::invalid_argument);
  ValvePredictiveValve played = v;  // a dither at 3 kHz is not 1/(2·n·T)
  played.model.width_a = 0.3;
  ValvePredictiveSettings half = settings(8);
  half.dither_fraction = 0.5;
  EXPECT_NO_THROW((void)valve_predictive_params(played, kT, kDitherHz, half));
  EXPECT_THROW((void)valve_predictive_params(played, kT, 3000.0, half), std::invalid_argument);
  ValvePredictiveSettings no_preview = settings(0);
  EXPECT_THROW((void)valve_predictive_params(v, kT, kDitherHz, no_preview), std::invalid_argument);
  ValvePredictiveSettings beyond = settings(8);
  beyond.headroom_fraction = 1.5;  // a box wider than the current's range
  EXPECT_THROW((void)valve_predictive_params(v, kT, kDitherHz, beyond), std::invalid_argument);
  ValvePredictiveGrid empty;
  empty.preview_samples.clear();
  EXPECT_THROW((void)design_valve_predictive(v, kT, kDitherHz, empty), std::invalid_argument);
}

TEST(ValvePredictiveLaw, RefusesADisabledOrMisshapenLaw) {
  EXPECT_THROW(ValvePredictiveLaw{ValvePredictiveParams{}}, std::invalid_argument);
  ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, settings(8));
  p.qp_linear.pop_back();
  EXPECT_THROW(ValvePredictiveLaw{p}, std::invalid_argument);
}

// On its own model a held reference is reached exactly, P samples after it is given: the
// disturbance state and the affine terms leave no offset, and the preview moves the spool before
// the reading's target does.
TEST(ValvePredictiveLaw, ReachesAHeldReferenceOnItsOwnModel) {
  const int preview = 10;
  const ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, settings(preview));
  ValvePredictiveLaw law(p);
  OwnModel plant(p, 0.0);
  const double target = 200e-6;
  std::vector<double> y;
  for (int k = 0; k < 3000; ++k) {
    const double reading = plant.reading();
    y.push_back(reading);
    plant.step(law.update(k >= 100 ? target : 0.0, reading));
  }
  // Nothing moves the reading before the law knows of the step.
  for (int k = 0; k <= 100; ++k) EXPECT_NEAR(y[static_cast<std::size_t>(k)], 0.0, 1e-9) << k;
  // The reading leaves before its target does (k = 100 + P) but not before the valve's delay.
  EXPECT_GT(y[100 + preview], 1e-6);
  EXPECT_NEAR(y.back(), target, 1e-9);
}

// An offset the law was not told of (a force current of 50 mA more than the model says, as a
// misidentified X_min or g would give): the Kalman filter's disturbance state finds it and the
// reading still settles on the reference.
TEST(ValvePredictiveLaw, RemovesAnOffsetItWasNotToldOf) {
  const ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, settings(10));
  ValvePredictiveLaw law(p);
  OwnModel plant(p, 100e-6);
  plant.z[kDisturbance] = 0.05;
  double worst_late = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double reading = plant.reading();
    if (k >= 15000) worst_late = std::max(worst_late, std::abs(reading - 100e-6));
    plant.step(law.update(100e-6, reading));
  }
  EXPECT_LT(worst_late, 0.1e-6);
}

// While the reference is held, the law corrects with the faster disturbance walk's gain: an offset
// it was not told of appears at a held reference and is gone within a fraction of the time the
// moving target's gain takes.
TEST(ValvePredictiveLaw, AHeldTargetGetsTheFasterDisturbanceEstimate) {
  ValvePredictiveSettings s = settings(10);
  s.disturbance_walk_a = 1e-6;
  s.held_disturbance_walk_a = 1e-4;
  const ValvePredictiveParams held = valve_predictive_params(linear_valve(), kT, kDitherHz, s);
  EXPECT_EQ(held.held_band_m, linear_valve().lvdt_noise_m);
  ValvePredictiveParams moving = held;
  moving.held_kalman_gain.clear();  // the moving target's gain throughout
  const auto settle_samples = [](const ValvePredictiveParams& p) {
    ValvePredictiveLaw law(p);
    OwnModel plant(p, 100e-6);
    int last_off = 0;
    for (int k = 0; k < 30000; ++k) {
      if (k == 1000) plant.z[kDisturbance] = 0.05;
      const double reading = plant.reading();
      if (std::abs(reading - 100e-6) > 0.5e-6) last_off = k;
      plant.step(law.update(100e-6, reading));
    }
    return last_off - 1000;
  };
  const int fast = settle_samples(held), slow = settle_samples(moving);
  EXPECT_GT(fast, 0);
  EXPECT_LT(fast, slow / 3) << "held " << fast << " samples, moving " << slow;
}

// A reference held over W samples and then stepped (a cascade's PI opening) is averaged over W:
// the law takes the line through the steps. Its commands then match those of the same law given
// that line, the mean of the last W references, to rounding.
TEST(ValvePredictiveLaw, AveragesTheReferenceOverItsWindow) {
  ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, settings(10));
  p.held_kalman_gain.clear();
  ValvePredictiveParams windowed = p;
  windowed.reference_window_samples = 10;
  ValvePredictiveLaw stairs(windowed), line(p);
  OwnModel a(p, 0.0), b(p, 0.0);
  std::vector<double> given(10, 0.0);
  double worst = 0.0, low = INFINITY, high = -INFINITY;
  for (int k = 0; k < 3000; ++k) {
    const double held = 200e-6 * std::sin(2.0 * 3.141592653589793 * 5.0 * kT * static_cast<double>(k - k % 10));
    given[static_cast<std::size_t>(k % 10)] = held;
    double mean = 0.0;
    for (double g : given) mean += g;
    mean /= 10.0;
    const double ua = stairs.update(held, a.reading()), ub = line.update(mean, b.reading());
    worst = std::max(worst, std::abs(ua - ub));
    low = std::min(low, ua);
    high = std::max(high, ua);
    a.step(ua);
    b.step(ub);
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(high - low, 0.1);  // the commands moved: the comparison was not of constants
  ValvePredictiveParams too_wide = p;
  too_wide.reference_window_samples = 0;
  EXPECT_THROW(ValvePredictiveLaw{too_wide}, std::invalid_argument);
}

// A step larger than the current can make in the horizon: the box holds every command, and binds.
TEST(ValvePredictiveLaw, KeepsItsCommandsInTheBox) {
  ValvePredictiveSettings s = settings(10);
  const ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, s);
  ValvePredictiveLaw law(p);
  OwnModel plant(p, -0.5e-3);
  int at_bound = 0;
  for (int k = 0; k < 2000; ++k) {
    const double reference = (k / 500) % 2 == 0 ? 0.8e-3 : -0.8e-3;
    const double command = law.update(reference, plant.reading());
    ASSERT_GE(command, p.lower_a);
    ASSERT_LE(command, p.upper_a);
    if (command == p.lower_a || command == p.upper_a) ++at_bound;
    plant.step(command);
  }
  EXPECT_GT(at_bound, 10);
}

// The QP at the design's size (P = 28, H = 78) on a square wave whose jumps bind most of the
// horizon: wherever the solver says it ended at the optimum, its commands meet the optimality
// conditions of the box QP computed here from the matrices themselves (the gradient H·U + F·x0 is
// zero on a free command, and points out of the box at a bound one); both ways of solving a step
// are exercised; no sample goes past the work budget, and the jumps are where it binds.
TEST(ValvePredictiveLaw, SolvesItsQpToOptimalityWithinItsBudget) {
  ValvePredictiveSettings s = settings(28);
  s.rate_weight_m2_per_a2 = 2e-11;
  const ValvePredictiveParams p = valve_predictive_params(linear_valve(), kT, kDitherHz, s);
  ASSERT_EQ(p.horizon_samples, 78);
  ValvePredictiveLaw law(p);
  OwnModel plant(p, 0.0);
  const int h = p.horizon_samples;
  const int n = static_cast<int>(p.qp_linear.size()) / h;
  int checked = 0, range_side = 0, free_side = 0, cut = 0;
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double reference = (k / 500) % 2 == 0 ? 0.6e-3 : -0.6e-3;
    plant.step(law.update(reference, plant.reading()));
    ASSERT_LE(law.last_qp_work(), ValvePredictiveLaw::kQpWorkBudget);
    if (!law.last_qp_complete()) {
      ++cut;
      continue;
    }
    const int bound = law.last_active_commands();
    if (bound > 0 && bound <= h - bound) ++range_side;
    if (bound > h - bound) ++free_side;
    const auto u = law.last_commands();
    const auto x0 = law.last_qp_state();
    double scale = 0.0;
    std::vector<double> g(static_cast<std::size_t>(h));
    for (int r = 0; r < h; ++r) {
      double v = 0.0;
      for (int c = 0; c < n; ++c) v += p.qp_linear[static_cast<std::size_t>(r * n + c)] * x0[static_cast<std::size_t>(c)];
      scale = std::max(scale, std::abs(v));
      for (int c = 0; c < h; ++c) v += p.qp_hessian[static_cast<std::size_t>(r * h + c)] * u[static_cast<std::size_t>(c)];
      g[static_cast<std::size_t>(r)] = v;
    }
    for (int r = 0; r < h; ++r) {
      const double ur = u[static_cast<std::size_t>(r)], gr = g[static_cast<std::size_t>(r)] / scale;
      ASSERT_GE(ur, p.lower_a - 1e-9) << "sample " << k << ", command " << r;
      ASSERT_LE(ur, p.upper_a + 1e-9) << "sample " << k << ", command " << r;
      const double wrong = ur == p.lower_a ? std::max(0.0, -gr) : ur == p.upper_a ? std::max(0.0, gr) : std::abs(gr);
      worst = std::max(worst, wrong);
    }
    ++checked;
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(checked, 2900);
  EXPECT_GT(range_side, 20);
  EXPECT_GT(free_side, 0);
  EXPECT_GT(cut, 0);  // the jumps
  EXPECT_LT(cut, 30);
}

// The dither rides on the box's command, within [0, I_max], and the sample allocates nothing.
TEST(ValvePredictiveLaw, DithersWithinTheLimitAndAllocatesNothing) {
  ValvePredictiveValve v = linear_valve();
  v.model.width_a = 0.3;
  ValvePredictiveSettings s = settings(10);
  s.dither_fraction = 0.75;
  const ValvePredictiveParams p = valve_predictive_params(v, kT, kDitherHz, s);
  EXPECT_DOUBLE_EQ(p.lower_a, 0.225);
  EXPECT_DOUBLE_EQ(p.upper_a, 3.0 - 0.225);
  EXPECT_EQ(p.dither_half_period_samples, 2);
  ValvePredictiveLaw law(p);
  OwnModel plant(p, 0.0);
  (void)law.update(0.0, plant.reading());
  const long before = hsa::test::thread_allocations();
  double low = INFINITY, high = -INFINITY;
  for (int k = 0; k < 4000; ++k) {
    const double command = law.update(std::sin(k * 1e-3) * 0.8e-3, plant.reading());
    low = std::min(low, command);
    high = std::max(high, command);
    plant.step(command);
  }
  EXPECT_EQ(hsa::test::thread_allocations() - before, 0);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, 3.0);
}

// The design keeps every grid point's figure and picks the least.
TEST(ValvePredictiveDesign, PicksTheLeastPeakOfItsGrid) {
  ValvePredictiveValve v;  // the paper's valve as the fit's model defaults describe it
  v.regulator_delay_s = 2e-4;
  v.current_max_a = 3.0;
  const ValvePredictiveGrid grid{.preview_samples = {8, 20}, .rate_weights_m2_per_a2 = {1e-10},
                                 .dither_fractions = {1.0}, .disturbance_walks_a = {1e-5},
                                 .headroom_fractions = {1.0}, .seeds = {1}};
  const ValvePredictiveDesign d = design_valve_predictive(v, kT, kDitherHz, grid);
  ASSERT_EQ(d.candidates.size(), 2u);
  const double least = std::min(d.candidates[0].peak_m, d.candidates[1].peak_m);
  EXPECT_EQ(d.peak_m, least);
  EXPECT_EQ(d.law.preview_samples, d.settings.preview_samples);
  EXPECT_EQ(d.law, valve_predictive_params(v, kT, kDitherHz, d.settings));
  EXPECT_EQ(predictive_triangle_peak(v, d.law, 1), d.peak_m);  // the same run, the same figure
}

}  // namespace
