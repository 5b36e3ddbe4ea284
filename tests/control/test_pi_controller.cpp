#include "control/pi_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "control/loop_analysis.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {
namespace {

// Values stay far below 1e-9 of the signals, so the exact arithmetic of the algorithm holds to
// rounding; 1e-12 leaves room for a few operations' rounding on values of order 1.
constexpr double kExact = 1e-12;

PiParams paper_params() { return PiParams{}; }  // Kp = 85 m⁻¹, Ki = 460 m⁻¹s⁻¹, T = 1 ms

TEST(PiController, DefaultsAreThePaperGainsInSi) {
  const PiParams p;
  EXPECT_EQ(p.kp, 85.0);
  EXPECT_EQ(p.ki, 460.0);
  EXPECT_EQ(p.period_s, 1e-3);
  EXPECT_EQ(p.output_limit, 1.0);
}

TEST(PiController, IntegratesByBackwardEuler) {
  PiController pi(paper_params());
  pi.activate(0.0);
  const double error = 1e-4;  // small enough never to saturate: 85·1e-4 + 460·0.01·1e-4 ≪ 1
  for (int k = 1; k <= 10; ++k) {
    const double u = pi.update(error, 0.0);
    const double integral = k * 460.0 * 1e-3 * error;
    EXPECT_NEAR(pi.integral(), integral, kExact);
    EXPECT_NEAR(u, 85.0 * error + integral, kExact);
    EXPECT_FALSE(pi.saturated());
  }
  EXPECT_EQ(pi.saturation_count(), 0u);
}

TEST(PiController, ClampsToTheOpeningRangeAndCountsSaturatedSamples) {
  PiController pi(paper_params());
  pi.activate(0.0);
  EXPECT_EQ(pi.update(0.1, 0.0), 1.0);  // 85·0.1 = 8.5
  EXPECT_TRUE(pi.saturated());
  EXPECT_EQ(pi.update(-0.1, 0.0), -1.0);
  EXPECT_TRUE(pi.saturated());
  EXPECT_EQ(pi.saturation_count(), 2u);
  pi.update(0.0, 0.0);
  EXPECT_FALSE(pi.saturated());
  EXPECT_EQ(pi.saturation_count(), 2u);
}

TEST(PiController, IntegratorFreezesWhileSaturatedInTheErrorsDirection) {
  for (const double sign : {1.0, -1.0}) {
    PiController pi(paper_params());
    pi.activate(0.0, 0.5 * sign);
    for (int k = 0; k < 1000; ++k) pi.update(sign * 0.05, 0.0);  // Kp·e = 4.25: saturated
    EXPECT_EQ(pi.output(), sign);
    EXPECT_EQ(pi.integral(), 0.5 * sign) << "a second of saturation must not wind the integral up";
    EXPECT_EQ(pi.saturation_count(), 1000u);

    // The error reverses to a small value: without windup the output leaves saturation at once.
    const double u = pi.update(-sign * 1e-3, 0.0);
    EXPECT_NEAR(u, sign * 0.5 - sign * (85.0 + 0.46) * 1e-3, kExact);
    EXPECT_FALSE(pi.saturated());
  }
}

class PiBumpless : public ::testing::TestWithParam<double> {};

TEST_P(PiBumpless, FirstOutputEqualsTheAppliedOpening) {
  const double rod = GetParam();
  for (const double applied : {-0.7, 0.0, 0.3, 1.0}) {
    PiController pi(paper_params());
    pi.activate(rod, applied);
    EXPECT_EQ(pi.output(), applied);
    EXPECT_NEAR(pi.update(rod, rod), applied, kExact);
  }
}

TEST_P(PiBumpless, RateLimitedStartFarFromTheSetpointMovesOnlyByOneRampStep) {
  const double rod = GetParam();
  PiParams p = paper_params();
  p.max_setpoint_rate_m_s = 0.02;
  PiController pi(p);
  pi.activate(rod, 0.3);
  const double first = pi.update(rod + 0.1, rod);  // commanded setpoint 100 mm away
  const double ramp_step = 0.02 * 1e-3;
  EXPECT_NEAR(std::abs(first - 0.3), (85.0 + 0.46) * ramp_step, kExact);
}

// Rod positions of Table A3, in metres.
INSTANTIATE_TEST_SUITE_P(TableA3Positions, PiBumpless,
                         ::testing::Values(0.01, 0.03, 0.06, 0.09, 0.12, 0.15, 0.18, 0.21, 0.24,
                                           0.27, 0.29));

TEST(PiController, SetpointRateLimit) {
  PiParams p = paper_params();
  p.max_setpoint_rate_m_s = 0.05;  // 50 µm per 1 ms sample
  PiController pi(p);
  pi.activate(0.1);
  for (int k = 1; k <= 250; ++k) {
    pi.update(0.11, 0.1);
    EXPECT_NEAR(pi.limited_setpoint(), std::min(0.1 + k * 5e-5, 0.11), kExact) << "sample " << k;
  }
  // Downwards the same.
  pi.update(0.0, 0.1);
  EXPECT_NEAR(pi.limited_setpoint(), 0.11 - 5e-5, kExact);
}

// The paper's PI with the given bands, started at the origin with the opening 0.2 applied.
PiController started_with_bands(double dead_band_m, double integral_dead_band_m) {
  PiParams p = paper_params();
  p.dead_band_m = dead_band_m;
  p.integral_dead_band_m = integral_dead_band_m;
  PiController pi(p);
  pi.activate(0.0, 0.2);
  return pi;
}

TEST(PiController, DeadBandIsContinuousAndHoldsTheIntegrator) {
  PiController pi = started_with_bands(1e-4, 0.0);
  for (const double e : {-1e-4, -5e-5, 0.0, 3e-5, 1e-4}) {
    EXPECT_NEAR(pi.update(e, 0.0), 0.2, kExact) << "error " << e << " lies inside the band";
    EXPECT_EQ(pi.integral(), 0.2);
  }
  // Just outside, the controller acts on the excess only, so there is no step at the edge.
  const double excess = 2e-6;
  EXPECT_NEAR(pi.update(1e-4 + excess, 0.0), 0.2 + (85.0 + 0.46) * excess, kExact);
  EXPECT_NEAR(pi.error(), excess, kExact);
}

TEST(PiController, IntegralDeadBandHoldsOnlyTheIntegrator) {
  PiController pi = started_with_bands(0.0, 5e-6);
  for (const double e : {-5e-6, -2e-6, 0.0, 1e-6, 5e-6}) {
    // The proportional term acts on the whole error; the integral holds.
    EXPECT_NEAR(pi.update(e, 0.0), 0.2 + 85.0 * e, kExact) << "error " << e << " lies inside the band";
    EXPECT_EQ(pi.integral(), 0.2);
    EXPECT_NEAR(pi.error(), e, kExact);
  }
  // Outside, the integrator takes the excess only, so its rate has no step at the edge.
  const double excess = 2e-6;
  EXPECT_NEAR(pi.update(-5e-6 - excess, 0.0), 0.2 - 85.0 * (5e-6 + excess) - 0.46 * excess, kExact);
  EXPECT_NEAR(pi.integral(), 0.2 - 0.46 * excess, kExact);
}

TEST(PiController, VelocityFeedforwardAddsKvTimesTheSetpointVelocity) {
  PiParams p = paper_params();
  p.velocity_feedforward = 5.0;  // opening per m/s
  PiController pi(p);
  pi.activate(0.1);
  EXPECT_NEAR(pi.update(0.1, 0.1, 0.02), 5.0 * 0.02, kExact);  // no error: the feed-forward alone
  EXPECT_NEAR(pi.integral(), 0.0, kExact);                      // it is not integrated
  const double e = 1e-4;
  const double u = pi.update(0.1 + e, 0.1, -0.01);
  EXPECT_NEAR(u, 85.0 * e + 460.0 * 1e-3 * e + 5.0 * -0.01, kExact);

  PiController off(paper_params());  // Kv = 0: the velocity is ignored
  off.activate(0.1);
  EXPECT_EQ(off.update(0.1, 0.1, 0.5), 0.0);
}

// u_ff = Kv·v + Ka·a + Kj·j (control/motion_feedforward.hpp): each term adds its own, none is
// integrated.
TEST(PiController, AccelerationAndJerkFeedforwardAddTheirTerms) {
  PiParams p = paper_params();
  p.velocity_feedforward = 4.0;
  p.acceleration_feedforward = 0.05;
  p.jerk_feedforward = 5e-4;
  PiController pi(p);
  pi.activate(0.1);
  EXPECT_NEAR(pi.update(0.1, 0.1, SetpointMotion{0.1, 1.5, -30.0}), 4.0 * 0.1 + 0.05 * 1.5 - 5e-4 * 30.0, kExact);
  EXPECT_NEAR(pi.integral(), 0.0, kExact);
  PiController off(paper_params());  // all three 0: ignored, even a non-finite one
  off.activate(0.1);
  EXPECT_EQ(off.update(0.1, 0.1, SetpointMotion{0.5, INFINITY, NAN}), 0.0);
}

// The inverse of the paper's nominal plant (eq 52): 1/k01, b1/(k01·b0), 1/(k01·b0) in SI.
TEST(PiController, NominalFeedforwardInvertsThePapersNominalPlant) {
  const double k01_m_s = 1.722e6 / 7692.0 * 1e-3;  // 0.2239 m/s at full opening
  EXPECT_NEAR(kNominalFeedforward.velocity, 1.0 / k01_m_s, 1e-9);
  EXPECT_NEAR(kNominalFeedforward.accel, 90.31 / (k01_m_s * 7692.0), 1e-12);
  EXPECT_NEAR(kNominalFeedforward.jerk, 1.0 / (k01_m_s * 7692.0), 1e-12);
  // A rod moving as u_ff asks on the plant: the opening a steady 0.1 m/s needs is 0.1 / k01.
  EXPECT_NEAR(feedforward_opening(kNominalFeedforward, {0.1, 0.0, 0.0}), 0.1 / k01_m_s, 1e-12);
}

// During a planned move the integrator holds what it had; once the move is over it integrates again.
TEST(PiController, APlannedMoveHoldsTheIntegrator) {
  PiController pi(paper_params());
  pi.activate(0.1, 0.05);
  const double e = 1e-3;
  pi.update(0.1 + e, 0.1, SetpointMotion{0.0, 0.0, 0.0, true});
  EXPECT_EQ(pi.integral(), 0.05);
  EXPECT_NEAR(pi.output(), 0.05 + 85.0 * e, kExact);
  pi.update(0.1 + e, 0.1, SetpointMotion{});
  EXPECT_NEAR(pi.integral(), 0.05 + 460.0 * 1e-3 * e, kExact);
  PiParams p = paper_params();
  p.hold_integral_while_planned = false;  // the plain PI integrates through a move
  PiController plain(p);
  plain.activate(0.1, 0.05);
  plain.update(0.1 + e, 0.1, SetpointMotion{0.0, 0.0, 0.0, true});
  EXPECT_NEAR(plain.integral(), 0.05 + 460.0 * 1e-3 * e, kExact);
}

TEST(PiController, FeedforwardCountsTowardsSaturationAndAntiWindup) {
  PiParams p = paper_params();
  p.velocity_feedforward = 10.0;
  PiController pi(p);
  pi.activate(0.0);
  // 10 · 0.2 m/s = 2 > 1: saturated, and with a positive error the integrator holds.
  EXPECT_EQ(pi.update(1e-4, 0.0, 0.2), 1.0);
  EXPECT_TRUE(pi.saturated());
  EXPECT_EQ(pi.integral(), 0.0);
}

// The new gains keep the last output, and the next sample is what the new PI makes of it: with
// the same error again, the output moves only by the new integral step.
TEST(PiController, GainChangeKeepsTheOutputAndActsFromTheNextSample) {
  PiParams p = paper_params();
  p.velocity_feedforward = 5.0;
  PiController pi(p);
  pi.activate(0.1, 0.2);
  const double e = 2e-3;
  const double u = pi.update(0.1 + e, 0.1, 0.01);
  ASSERT_FALSE(pi.saturated());
  ASSERT_TRUE(pi.set_gains(30.0, 900.0));
  EXPECT_EQ(pi.output(), u);
  EXPECT_NEAR(30.0 * pi.error() + pi.integral() + 5.0 * 0.01, u, kExact);
  EXPECT_EQ(pi.params().kp, 30.0);
  EXPECT_EQ(pi.params().ki, 900.0);
  EXPECT_NEAR(pi.update(0.1 + e, 0.1, 0.01), u + 900.0 * 1e-3 * e, kExact);
}

// From saturation the integral takes the clamped output: the next sample leaves the clamp as soon
// as the error allows instead of unwinding an excess first.
TEST(PiController, GainChangeInSaturationStartsFromTheClampedOutput) {
  PiController pi(paper_params());
  pi.activate(0.0);
  EXPECT_EQ(pi.update(0.05, 0.0), 1.0);  // 85 · 0.05 = 4.25 > 1
  ASSERT_TRUE(pi.saturated());
  ASSERT_TRUE(pi.set_gains(10.0, 460.0));
  EXPECT_FALSE(pi.saturated());
  EXPECT_NEAR(10.0 * 0.05 + pi.integral(), 1.0, kExact);
  // The error halves: the new PI answers at once with 10 · 0.025 less (plus the integral step).
  EXPECT_NEAR(pi.update(0.025, 0.0), 1.0 - 10.0 * 0.025 + 460.0 * 1e-3 * 0.025, kExact);
}

TEST(PiController, GainChangeRefusesWhatTheConstructorRefuses) {
  PiController pi(paper_params());
  pi.activate(0.0, 0.3);
  EXPECT_FALSE(pi.set_gains(-1.0, 460.0));
  EXPECT_FALSE(pi.set_gains(85.0, -1.0));
  EXPECT_FALSE(pi.set_gains(std::nan(""), 460.0));
  EXPECT_FALSE(pi.set_gains(85.0, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(pi.params().kp, 85.0);
  EXPECT_EQ(pi.params().ki, 460.0);
  EXPECT_EQ(pi.integral(), 0.3);
}

TEST(PiController, RejectsInvalidParameters) {
  auto with = [](auto change) {
    PiParams p;
    change(p);
    return p;
  };
  EXPECT_THROW(PiController(with([](PiParams& p) { p.period_s = 0.0; })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.output_limit = -1.0; })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.kp = -1.0; })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.ki = std::nan(""); })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.max_setpoint_rate_m_s = 0.0; })),
               std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.dead_band_m = -1e-6; })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.integral_dead_band_m = -1e-6; })), std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.integral_dead_band_m = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.velocity_feedforward = -1.0; })),
               std::invalid_argument);
  EXPECT_THROW(PiController(with([](PiParams& p) { p.velocity_feedforward = INFINITY; })),
               std::invalid_argument);
}

// The discrete PI in SI units on the nominal plant P0 (mm per unit opening), held through an
// exact zero-order hold at 1 kHz: a 10 mm step must reproduce the continuous analysis. This ties
// the controller's units and signs to the analysis' explicit mm conversion.
TEST(PiController, ClosesTheNominalPlantLikeTheContinuousAnalysis) {
  const CylinderPlant p0 = kNominalPlant;
  constexpr double kT = 1e-3;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();  // [A B; 0 0]·T, state (y_mm, y', y'')
  m(0, 1) = 1.0;
  m(1, 2) = 1.0;
  m(2, 1) = -p0.b0;
  m(2, 2) = -p0.b1;
  m(2, 3) = p0.gain;
  const Eigen::Matrix4d e = (m * kT).exp();
  const Eigen::Matrix3d phi = e.topLeftCorner<3, 3>();
  const Eigen::Vector3d gamma = e.topRightCorner<3, 1>();

  PiController pi(paper_params());
  pi.activate(0.0);
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  const double step_m = 0.01;  // Kp·10 mm = 0.85: the loop stays linear
  double peak = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double u = pi.update(step_m, x(0) * 1e-3);
    x = phi * x + gamma * u;
    peak = std::max(peak, x(0) * 1e-3);
  }
  EXPECT_EQ(pi.saturation_count(), 0u);
  EXPECT_NEAR(x(0) * 1e-3, step_m, 1e-6);
  const double discrete_overshoot = (peak / step_m - 1.0) * 100.0;
  const double continuous_overshoot = step_metrics(p0, {85.0, 460.0}).overshoot_pct;
  // Sampling and hold at 1 kHz cost about ω_c·T/2 = 20 rad/s · 0.5 ms ≈ 0.6° of phase margin,
  // worth a few tenths of a point of overshoot, and only ever more overshoot.
  EXPECT_GT(discrete_overshoot, continuous_overshoot);
  EXPECT_LT(discrete_overshoot, continuous_overshoot + 0.5);
}

}  // namespace
}  // namespace hsa::control
