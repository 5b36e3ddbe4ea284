#include "sim/proportional_valve.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace hsa::sim {
namespace {

constexpr double kStep = 1e-4;

// Steps the valve for duration_s with a constant reference.
void hold(ProportionalValve& valve, double current_a, double duration_s) {
  const auto steps = std::lround(duration_s / valve.step_s());
  for (long i = 0; i < steps; ++i) {
    valve.step(current_a);
  }
}

TEST(ProportionalValve, StartsDeEnergizedOnTheRestStop) {
  const ProportionalValve valve({}, kStep);
  EXPECT_DOUBLE_EQ(valve.position(), -2.5e-3);
  EXPECT_DOUBLE_EQ(valve.velocity(), 0.0);
  EXPECT_DOUBLE_EQ(valve.current(), 0.0);
  EXPECT_DOUBLE_EQ(valve.opening(), 0.0);  // fail-safe: ports blocked
}

TEST(ProportionalValve, CurrentRegulatorDelaysByTwoTenthsOfAMillisecond) {
  ProportionalValve valve({}, kStep);
  hold(valve, 0.5, 0.01);
  valve.step(1.5);  // 0.1 ms after the change: still the old reference
  EXPECT_NEAR(valve.current(), 0.5, 1.5e-3);
  valve.step(1.5);  // 0.2 ms: the new one
  EXPECT_NEAR(valve.current(), 1.5, 1.5e-3);
}

TEST(ProportionalValve, CurrentDelayIsInTimeNotInSteps) {
  ProportionalValve valve({}, 25e-6);
  hold(valve, 0.5, 0.01);
  for (int i = 0; i < 7; ++i) {
    valve.step(1.5);
    EXPECT_NEAR(valve.current(), 0.5, 1.5e-3) << "after step " << i + 1;
  }
  valve.step(1.5);
  EXPECT_NEAR(valve.current(), 1.5, 1.5e-3);
}

TEST(ProportionalValve, CurrentErrorIsBoundedAndNotZero) {
  ProportionalValve valve({}, kStep);
  double previous_reference = valve.current();
  double max_error = 0.0;
  double min_error = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const double reference = 0.5 + 2.0 * std::abs(std::sin(1e-3 * n));  // inside (0, I_max)
    valve.step(reference);
    // After a call the current is the reference of the call before (0.2 ms = 2 steps).
    const double error = valve.current() - previous_reference;
    max_error = std::max(max_error, error);
    min_error = std::min(min_error, error);
    previous_reference = reference;
  }
  EXPECT_LE(max_error, 1.5e-3);
  EXPECT_GE(min_error, -1.5e-3);
  EXPECT_GT(max_error, 1.0e-3);  // the error is really there, both ways
  EXPECT_LT(min_error, -1.0e-3);
}

TEST(ProportionalValve, CurrentReferenceIsClampedToTheAmplifierRange) {
  ProportionalValve valve({}, kStep);
  hold(valve, 10.0, 0.01);
  EXPECT_NEAR(valve.current(), 3.0, 1.5e-3);
  hold(valve, -2.0, 0.01);
  EXPECT_GE(valve.current(), 0.0);
  EXPECT_LE(valve.current(), 1.5e-3);
}

TEST(ProportionalValve, SmallReversalsStayInsideTheDeadBand) {
  ProportionalValve valve({}, kStep);
  hold(valve, 2.0, 0.05);  // rising edge: c settles at I - w
  const double c_high = valve.force_current();
  EXPECT_NEAR(c_high, 1.7, 2e-3);

  hold(valve, 2.0 - 0.25, 0.05);  // reverse by less than the width: the force does not move
  EXPECT_NEAR(valve.force_current(), c_high, 2e-3);

  hold(valve, 2.0 - 0.35, 0.05);  // by more: c follows the falling edge, c = I
  EXPECT_NEAR(valve.force_current(), 1.65, 2e-3);

  hold(valve, 1.65 + 0.25, 0.05);  // and back up by less than the width: still nothing
  EXPECT_NEAR(valve.force_current(), 1.65, 2e-3);
}

TEST(ProportionalValve, ForceCurrentLagsByTauA) {
  ProportionalValve valve({}, kStep);
  hold(valve, 1.0, 0.05);  // c = 0.7
  const double c0 = valve.force_current();
  hold(valve, 2.0, 0.2e-3);  // the change reaches the solenoid now
  const double c_start = valve.force_current();
  hold(valve, 2.0, 1.5e-3);  // one tau_a later: 63 % of the way to 1.7
  EXPECT_NEAR(c_start, c0, 2e-3);
  EXPECT_NEAR((valve.force_current() - c0) / (1.7 - c0), 1.0 - std::exp(-1.0), 0.02);
}

TEST(ProportionalValve, BiasCurrentHoldsHydraulicZero) {
  ProportionalValve valve({}, kStep);
  const double i0 = valve.bias_current();
  EXPECT_GT(i0, 1.2);  // mid-range of 0 ... 3 A
  EXPECT_LT(i0, 1.8);
  valve.reset(0.0);
  EXPECT_DOUBLE_EQ(valve.current(), i0);
  hold(valve, i0, 1.0);
  EXPECT_NEAR(valve.position(), 0.0, 1e-6);
  EXPECT_NEAR(valve.opening(), 0.0, 1e-3);
}

TEST(ProportionalValve, BiasCurrentApproachedFromRestReachesZeroAfterTheDeadBand) {
  ProportionalValve valve({}, kStep);  // on the rest stop, no current
  const double w = valve.parameters().hysteresis_width_a;
  const double target = valve.bias_current() + 0.5 * w;  // the rising edge
  for (int i = 1; i <= 5000; ++i) {                      // slow ramp, 0.5 s
    valve.step(target * i / 5000.0);
  }
  hold(valve, target, 0.5);
  const double stick_band = valve.parameters().coulomb_friction_n / valve.spring_stiffness();
  EXPECT_NEAR(valve.position(), 0.0, stick_band + 2e-6);
}

TEST(ProportionalValve, StaticGainFollowsSpringAndForceConstant) {
  const ProportionalValveParameters p{};
  ProportionalValve valve(p, kStep);
  valve.reset(0.0);
  const double i = valve.bias_current() + 0.5;  // 0.35 A past the upper edge of the band
  hold(valve, i, 0.5);
  const double k = p.moving_mass_kg * std::pow(2.0 * std::numbers::pi * p.natural_frequency_hz, 2);
  const double c = i - p.hysteresis_width_a;  // the rising edge of the dead band
  const double expected = p.stroke_min_m + p.force_constant_n_per_a * c / k;
  EXPECT_NEAR(valve.position(), expected, p.coulomb_friction_n / k + 2e-6);
  EXPECT_GT(valve.position(), 0.5e-3);  // it did move
}

TEST(ProportionalValve, SpoolResonanceIsNearFiftyHertz) {
  ProportionalValve valve({}, kStep);
  valve.reset(0.0);
  // A step down beyond the dead band excites the mass-spring mode; the time between successive
  // velocity reversals is half the damped period (Coulomb friction does not change it).
  const double i = valve.bias_current() - 0.5;
  std::vector<double> reversals;
  double previous_v = 0.0;
  for (int n = 1; n <= 1000 && reversals.size() < 3; ++n) {
    valve.step(i);
    const double v = valve.velocity();
    if (previous_v != 0.0 && v * previous_v <= 0.0) {
      reversals.push_back(n * kStep);
    }
    if (v != 0.0) {
      previous_v = v;
    }
  }
  ASSERT_GE(reversals.size(), 2u);
  const double damped_hz = 1.0 / (2.0 * (reversals[1] - reversals[0]));
  const double zeta = valve.parameters().damping_ratio;
  const double natural_hz = damped_hz / std::sqrt(1.0 - zeta * zeta);
  EXPECT_NEAR(natural_hz, 50.0, 1.5);
}

TEST(ProportionalValve, StrokeLimitsHold) {
  const ProportionalValveParameters p{};
  ProportionalValve valve(p, kStep);
  valve.reset(0.0);
  double lowest = 0.0;
  for (int n = 0; n < 2000; ++n) {
    valve.step(0.0);
    lowest = std::min(lowest, valve.position());
  }
  EXPECT_DOUBLE_EQ(valve.position(), p.stroke_min_m);
  EXPECT_DOUBLE_EQ(lowest, p.stroke_min_m);
  EXPECT_DOUBLE_EQ(valve.velocity(), 0.0);
  EXPECT_DOUBLE_EQ(valve.opening(), 0.0);

  double highest = p.stroke_min_m;
  for (int n = 0; n < 2000; ++n) {
    valve.step(p.current_max_a);
    highest = std::max(highest, valve.position());
  }
  EXPECT_DOUBLE_EQ(valve.position(), p.stroke_max_m);
  EXPECT_DOUBLE_EQ(highest, p.stroke_max_m);
  EXPECT_DOUBLE_EQ(valve.velocity(), 0.0);
  EXPECT_DOUBLE_EQ(valve.opening(), 1.0);
}

TEST(ProportionalValve, OpeningMapsTheSpoolTravel) {
  ProportionalValve valve({}, kStep);
  const struct {
    double x;
    double opening;
  } cases[] = {{0.0, 0.0},       {0.625e-3, 0.5},  {1.25e-3, 1.0},  {-0.625e-3, -0.5},
               {-1.25e-3, -1.0}, {-1.5625e-3, -0.5}, {-1.875e-3, 0.0}, {-2.0e-3, 0.0},
               {-2.5e-3, 0.0},   {5e-3, 1.0}};
  for (const auto& c : cases) {
    valve.reset(c.x);
    EXPECT_NEAR(valve.opening(), c.opening, 1e-12) << "x = " << c.x;
  }
}

TEST(ProportionalValve, ResetIsAnEquilibrium) {
  for (const double x : {-1.0e-3, 0.0, 0.8e-3}) {
    ProportionalValve valve({}, kStep);
    valve.reset(x);
    hold(valve, valve.hold_current(x), 0.5);
    EXPECT_NEAR(valve.position(), x, 1e-6) << "x = " << x;
  }
}

TEST(ProportionalValve, StuckSpoolDoesNotMove) {
  ProportionalValve valve({}, kStep);
  valve.reset(0.0);
  hold(valve, valve.bias_current() + 0.6, 5e-3);  // moving up when it seizes
  ASSERT_GT(valve.velocity(), 0.0);
  const double x = valve.position();
  valve.set_stuck(true);
  EXPECT_TRUE(valve.stuck());
  hold(valve, 3.0, 0.1);
  EXPECT_DOUBLE_EQ(valve.position(), x);
  EXPECT_DOUBLE_EQ(valve.velocity(), 0.0);
  hold(valve, 0.0, 0.1);
  EXPECT_DOUBLE_EQ(valve.position(), x);

  valve.set_stuck(false);  // freed with zero current: the spring takes it back to rest
  hold(valve, 0.0, 0.2);
  EXPECT_DOUBLE_EQ(valve.position(), valve.parameters().stroke_min_m);
}

TEST(ProportionalValve, SameSeedSameTrajectoryOtherSeedOtherNoise) {
  ProportionalValveParameters p{};
  p.seed = 42;
  ProportionalValve a(p, kStep);
  ProportionalValve b(p, kStep);
  p.seed = 43;
  ProportionalValve c(p, kStep);
  int differing_currents = 0;
  for (int n = 0; n < 5000; ++n) {
    const double reference = 1.5 + std::sin(2.0 * std::numbers::pi * 20.0 * n * kStep);
    a.step(reference);
    b.step(reference);
    c.step(reference);
    ASSERT_EQ(a.current(), b.current()) << "step " << n;
    ASSERT_EQ(a.position(), b.position()) << "step " << n;
    ASSERT_EQ(a.velocity(), b.velocity()) << "step " << n;
    differing_currents += a.current() != c.current() ? 1 : 0;
  }
  EXPECT_GT(differing_currents, 4900);

  a.reset(0.0);  // reset restarts the random sequence too
  ProportionalValve fresh(a.parameters(), kStep);
  fresh.reset(0.0);
  for (int n = 0; n < 100; ++n) {
    a.step(1.0);
    fresh.step(1.0);
    ASSERT_EQ(a.current(), fresh.current());
  }
}

TEST(ProportionalValve, SmallerStepGivesTheSameTrajectory) {
  ProportionalValve coarse({}, 1e-4);
  ProportionalValve fine({}, 1e-5);
  coarse.reset(0.0);
  fine.reset(0.0);
  const double i = coarse.bias_current() + 0.6;
  double worst = 0.0;
  for (int n = 0; n < 500; ++n) {
    coarse.step(i);
    for (int k = 0; k < 10; ++k) {
      fine.step(i);
    }
    worst = std::max(worst, std::abs(coarse.position() - fine.position()));
  }
  EXPECT_LT(worst, 10e-6);  // the rising edge is 0.2 ms either way; the rest is integration error
}

TEST(ProportionalValve, RejectsAStepLongerThanTheCurrentDelay) {
  EXPECT_THROW(ProportionalValve({}, 1e-3), std::invalid_argument);
  EXPECT_THROW(ProportionalValve({}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::sim
