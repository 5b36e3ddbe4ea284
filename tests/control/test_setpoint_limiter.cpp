// control::SetpointLimiter: the bounds hold on every sample (checked by finite differences of the
// output, not by its own velocity), a static target is reached without overshoot in the time a
// bang-bang profile takes, a target that moves within the bounds is followed exactly, the
// position bounds hold against a target that runs into them, and bad input changes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "control/setpoint_limiter.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

constexpr double kV = 0.15;   // the example axis's speed and acceleration (systemd/hsad-sim.toml)
constexpr double kA = 1.5;
constexpr double kT = 1e-4;   // hsad's base period
// Rounding of the finite differences: a few ulps of a position of 0.3 m over T and T².
constexpr double kSpeedSlack = 1e-9;
constexpr double kAccelSlack = 1e-5;

SetpointLimits limits() { return {kV, kA, 0.01, 0.29}; }

// Runs the limiter on target(t) for `seconds`, checking the bounds by finite differences of the
// output at every step.
template <class Target>
void run_checked(SetpointLimiter& l, Target&& target, double seconds) {
  double x_prev = l.position_m();
  double dx_prev = std::numeric_limits<double>::quiet_NaN();
  const auto steps = static_cast<long>(std::llround(seconds / kT));
  for (long k = 1; k <= steps; ++k) {
    const auto [r, r_dot] = target(k * kT);
    ASSERT_TRUE(l.step(r, r_dot, kT));
    const double x = l.position_m();
    const double dx = (x - x_prev) / kT;
    ASSERT_LE(std::abs(dx), kV + kSpeedSlack) << "speed at step " << k;
    if (std::isfinite(dx_prev)) {
      ASSERT_LE(std::abs(dx - dx_prev) / kT, kA + kAccelSlack) << "accel at step " << k;
    }
    ASSERT_GE(x, limits().low_m);
    ASSERT_LE(x, limits().high_m);
    x_prev = x;
    dx_prev = dx;
  }
}

struct Sample {
  double r, r_dot;
};

TEST(SetpointLimiter, BoundsHoldOnStepsSinesAndSquareWaves) {
  SetpointLimiter l(limits());
  l.reset(0.15);
  run_checked(l, [](double) { return Sample{0.29, 0.0}; }, 3.0);                    // full-stroke step up
  run_checked(l, [](double) { return Sample{0.01, 0.0}; }, 3.0);                    // and down
  run_checked(l, [](double t) {                                                     // 100 mm at 2 Hz
    const double w = 2 * M_PI * 2.0;
    return Sample{0.15 + 0.1 * std::sin(w * t), 0.1 * w * std::cos(w * t)};
  }, 3.0);
  run_checked(l, [](double t) { return Sample{std::fmod(t, 0.5) < 0.25 ? 0.28 : 0.02, 0.0}; }, 3.0);
  run_checked(l, [](double t) { return Sample{0.15 + 0.002 * std::sin(1e4 * t), 0.0}; }, 1.0);  // noise
}

TEST(SetpointLimiter, ReachesAStaticTargetWithoutOvershootInTheBangBangTime) {
  for (const double distance : {0.1, 0.005, 0.0002, -0.27}) {
    const double start = distance > 0 ? 0.02 : 0.28;
    const double target = start + distance;
    SetpointLimiter l(limits());
    l.reset(start);
    // Closed form: accelerate at A, cruise at V if the distance allows, brake at A.
    const double d = std::abs(distance);
    const double bang_bang_s = d >= kV * kV / kA ? d / kV + kV / kA : 2.0 * std::sqrt(d / kA);
    double overshoot = 0.0;
    long steps = 0;
    while (!(l.position_m() == target && l.velocity_m_s() == 0.0) && steps < 100'000) {
      ASSERT_TRUE(l.step(target, 0.0, kT));
      overshoot = std::max(overshoot, (l.position_m() - target) * (distance > 0 ? 1.0 : -1.0));
      ++steps;
    }
    const double reached_s = steps * kT;
    std::printf("%+8.4f m: reached in %.4f s, bang-bang %.4f s, overshoot %.3g m\n", distance, reached_s,
                bang_bang_s, overshoot);
    EXPECT_LE(overshoot, 0.0) << distance;  // exactly: the last step lands on the target
    // Time-optimal to the sampling: no more than a few steps over the continuous optimum (the
    // discrete braking lands on the target within the last steps), and never faster.
    EXPECT_GE(reached_s, bang_bang_s - kT) << distance;
    EXPECT_LE(reached_s, bang_bang_s + 10 * kT) << distance;
    // It stays there.
    for (int i = 0; i < 1000; ++i) ASSERT_TRUE(l.step(target, 0.0, kT));
    EXPECT_EQ(l.position_m(), target);
    EXPECT_EQ(l.velocity_m_s(), 0.0);
  }
}

TEST(SetpointLimiter, FollowsARampWithinTheBoundsExactly) {
  SetpointLimiter l(limits());
  const double speed = 0.05;  // a third of V
  l.reset(0.05, speed);       // on the ramp already: nothing to catch up
  double worst = 0.0;
  for (long k = 1; k <= 20'000; ++k) {  // 2 s: 0.05 -> 0.15
    const double r = 0.05 + speed * k * kT;
    ASSERT_TRUE(l.step(r, speed, kT));
    worst = std::max(worst, std::abs(l.position_m() - r));
    ASSERT_NEAR(l.velocity_m_s(), speed, 1e-12);
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_LE(std::abs(l.lag_m()), 1e-12);
}

TEST(SetpointLimiter, CatchesUpWithARampStartedFromRestAndThenFollowsIt) {
  SetpointLimiter l(limits());
  const double speed = 0.1;
  l.reset(0.05);
  double late_error = 0.0;
  for (long k = 1; k <= 15'000; ++k) {
    const double r = 0.05 + speed * k * kT;
    ASSERT_TRUE(l.step(r, speed, kT));
    if (k * kT > 0.5) late_error = std::max(late_error, std::abs(l.position_m() - r));
  }
  EXPECT_LE(late_error, 1e-9);
}

TEST(SetpointLimiter, FollowsASineWithinTheBounds) {
  // 20 mm at 1 Hz: 0.126 m/s and 0.79 m/s² at most, inside V and A.
  SetpointLimiter l(limits());
  const double w = 2 * M_PI;
  l.reset(0.15, 0.02 * w);
  double worst = 0.0;
  for (long k = 1; k <= 20'000; ++k) {
    const double t = k * kT;
    ASSERT_TRUE(l.step(0.15 + 0.02 * std::sin(w * t), 0.02 * w * std::cos(w * t), kT));
    worst = std::max(worst, std::abs(l.position_m() - (0.15 + 0.02 * std::sin(w * t))));
  }
  EXPECT_LE(worst, 1e-6);
}

TEST(SetpointLimiter, ATargetRunningIntoABoundCannotCarryTheOutputPastIt) {
  SetpointLimiter l(limits());
  l.reset(0.2, kV);
  // The target runs at V up to high and stops there (as the supervisor's clamp makes it do).
  double highest = 0.0;
  for (long k = 1; k <= 20'000; ++k) {
    const double r = std::min(0.2 + kV * k * kT, 0.29);
    ASSERT_TRUE(l.step(r, r < 0.29 ? kV : 0.0, kT));
    highest = std::max(highest, l.position_m());
  }
  EXPECT_LE(highest, 0.29);
  EXPECT_NEAR(l.position_m(), 0.29, 1e-9);
  // Beyond the bound: clamped, and the target's velocity is not followed out of the bounds.
  ASSERT_TRUE(l.step(0.5, 1.0, kT));
  EXPECT_LE(l.position_m(), 0.29);
}

TEST(SetpointLimiter, NonFiniteInputIsRefusedAndChangesNothing) {
  SetpointLimiter l(limits());
  l.reset(0.1, 0.05);
  ASSERT_TRUE(l.step(0.2, 0.0, kT));
  const double x = l.position_m(), v = l.velocity_m_s(), a = l.accel_m_s2(), lag = l.lag_m();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(l.step(nan, 0.0, kT));
  EXPECT_FALSE(l.step(inf, 0.0, kT));
  EXPECT_FALSE(l.step(-inf, 0.0, kT));
  EXPECT_FALSE(l.step(0.2, nan, kT));
  EXPECT_FALSE(l.step(0.2, inf, kT));
  EXPECT_FALSE(l.step(0.2, 0.0, 0.0));
  EXPECT_FALSE(l.step(0.2, 0.0, -kT));
  EXPECT_FALSE(l.step(0.2, 0.0, nan));
  EXPECT_FALSE(l.step(0.2, 0.0, inf));
  EXPECT_EQ(l.position_m(), x);
  EXPECT_EQ(l.velocity_m_s(), v);
  EXPECT_EQ(l.accel_m_s2(), a);
  EXPECT_EQ(l.lag_m(), lag);
}

TEST(SetpointLimiter, BadLimitsAreRefused) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(SetpointLimiter({0.0, kA}), std::invalid_argument);
  EXPECT_THROW(SetpointLimiter({inf, kA}), std::invalid_argument);
  EXPECT_THROW(SetpointLimiter({kV, -1.0}), std::invalid_argument);
  EXPECT_THROW(SetpointLimiter({kV, inf}), std::invalid_argument);
  EXPECT_THROW(SetpointLimiter({kV, kA, 0.3, 0.1}), std::invalid_argument);
  EXPECT_NO_THROW(SetpointLimiter({kV, kA, 0.1, 0.3}));
}

TEST(SetpointLimiter, StepAllocatesNothing) {
  SetpointLimiter l(limits());
  l.reset(0.1);
  const long before = test::thread_allocations();
  for (int k = 0; k < 1000; ++k) (void)l.step(0.2, 0.0, kT);
  EXPECT_EQ(test::thread_allocations(), before);
}

}  // namespace
}  // namespace hsa::control
