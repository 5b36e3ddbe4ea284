// The point-to-point profile: it ends at rest on the target, its speed, acceleration and jerk,
// measured by finite differences of the positions it gives, stay within their bounds, and the
// derivatives it reports are those of its positions. An infinite jerk bound is the trapezoid.
#include "control/jerk_limited_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hsa::control {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Largest |speed|, |acceleration| and |jerk| seen by differencing position() on a fine grid, and
// how far the reported derivatives are from those differences.
struct Measured {
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_jerk = 0.0;
  double velocity_mismatch = 0.0;
  double accel_mismatch = 0.0;
};

Measured measure(const JerkLimitedProfile& p, double dt = 1e-5) {
  Measured m;
  double v_prev = 0.0, a_prev = 0.0;
  for (double t = -0.01; t <= p.duration_s() + 0.01; t += dt) {
    const double v = (p.position(t + dt) - p.position(t)) / dt;  // at t + dt/2
    const double a = (v - v_prev) / dt;                           // at t
    m.max_speed = std::max(m.max_speed, std::abs(v));
    m.max_accel = std::max(m.max_accel, std::abs(a));
    m.max_jerk = std::max(m.max_jerk, std::abs(a - a_prev) / dt);
    m.velocity_mismatch = std::max(m.velocity_mismatch, std::abs(p.at(t + 0.5 * dt).velocity_m_s - v));
    m.accel_mismatch = std::max(m.accel_mismatch, std::abs(p.at(t + 0.5 * dt).accel_m_s2 -
                                                           (p.at(t + dt).velocity_m_s - p.at(t).velocity_m_s) / dt));
    v_prev = v;
    a_prev = a;
  }
  return m;
}

TEST(JerkLimitedProfile, ALongMoveReachesEveryBoundAndEndsAtRestOnTheTarget) {
  // 260 mm at 0.15 m/s, 1.5 m/s², 30 m/s³: T_j = 0.05 s, T_a = 0.15 s, 22.5 mm per phase.
  const JerkLimitedProfile p(0.020, 0.280, {0.15, 1.5, 30.0});
  EXPECT_DOUBLE_EQ(p.peak_speed_m_s(), 0.15);
  EXPECT_DOUBLE_EQ(p.peak_accel_m_s2(), 1.5);
  EXPECT_NEAR(p.duration_s(), 2 * 0.15 + (0.260 - 0.15 * 0.15) / 0.15, 1e-12);
  EXPECT_DOUBLE_EQ(p.position(0.0), 0.020);
  EXPECT_NEAR(p.position(0.05), 0.020 + 30.0 * std::pow(0.05, 3) / 6, 1e-12);  // end of the first jerk ramp
  EXPECT_NEAR(p.position(0.15), 0.020 + 0.15 * 0.15 / 2, 1e-12);              // end of the acceleration
  EXPECT_NEAR(p.position(p.duration_s() / 2), 0.150, 1e-12);                  // the middle
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.280);
  EXPECT_DOUBLE_EQ(p.position(10.0), 0.280);
  const MotionSample end = p.at(10.0);
  EXPECT_EQ(end.velocity_m_s, 0.0);
  EXPECT_EQ(end.accel_m_s2, 0.0);
  EXPECT_EQ(end.jerk_m_s3, 0.0);
  EXPECT_DOUBLE_EQ(p.at(0.025).jerk_m_s3, 30.0);
  EXPECT_DOUBLE_EQ(p.at(0.125).jerk_m_s3, -30.0);
  EXPECT_DOUBLE_EQ(p.at(0.1).accel_m_s2, 1.5);

  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, 0.15 * (1 + 1e-6));
  EXPECT_GT(m.max_speed, 0.15 * (1 - 1e-6));
  EXPECT_LE(m.max_accel, 1.5 * (1 + 1e-3));
  EXPECT_GT(m.max_accel, 1.5 * (1 - 1e-3));
  EXPECT_LE(m.max_jerk, 30.0 * 1.01);  // second differences at the corners
  EXPECT_LT(m.velocity_mismatch, 1e-6);
  EXPECT_LT(m.accel_mismatch, 1e-3);
}

TEST(JerkLimitedProfile, ItIsPointSymmetricAboutItsMiddleAndEitherDirectionMirrorsTheOther) {
  const JerkLimitedProfile up(0.060, 0.200, {0.15, 1.5, 30.0});
  const JerkLimitedProfile down(0.200, 0.060, {0.15, 1.5, 30.0});
  const double T = up.duration_s();
  EXPECT_DOUBLE_EQ(down.duration_s(), T);
  for (double t = 0.0; t <= T; t += T / 97) {
    // s(t) + s(T − t) = d, v(t) = v(T − t), a(t) = −a(T − t).
    EXPECT_NEAR(up.position(t) - 0.060 + up.position(T - t) - 0.060, 0.140, 1e-12);
    EXPECT_NEAR(up.at(t).velocity_m_s, up.at(T - t).velocity_m_s, 1e-12);
    EXPECT_NEAR(up.at(t).accel_m_s2, -up.at(T - t).accel_m_s2, 1e-9);
    EXPECT_NEAR(down.position(t) - 0.200, -(up.position(t) - 0.060), 1e-12);
    EXPECT_NEAR(down.at(t).velocity_m_s, -up.at(t).velocity_m_s, 1e-12);
    EXPECT_NEAR(down.at(t).jerk_m_s3, -up.at(t).jerk_m_s3, 1e-12);
  }
}

TEST(JerkLimitedProfile, AShortMoveReachesNeitherSpeedNorAccelerationAndStaysWithinBoth) {
  // 1 mm: below a²/j = 75 mm/s and below the speed, so the peak is (d²·j/4)^(1/3).
  const JerkLimitedProfile p(0.150, 0.149, {0.15, 1.5, 30.0});
  const double vp = std::cbrt(1e-6 * 30.0 / 4);
  EXPECT_NEAR(p.peak_speed_m_s(), vp, 1e-12);
  EXPECT_NEAR(p.peak_accel_m_s2(), std::sqrt(vp * 30.0), 1e-9);
  EXPECT_LT(p.peak_accel_m_s2(), 1.5);
  EXPECT_NEAR(p.duration_s(), 4 * std::sqrt(vp / 30.0), 1e-12);  // no cruise, no constant acceleration
  EXPECT_LT(p.velocity(0.01), 0.0);                               // downwards
  EXPECT_NEAR(p.position(p.duration_s() / 2), 0.1495, 1e-12);
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.149);
  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, vp * (1 + 1e-6));
  EXPECT_LE(m.max_accel, p.peak_accel_m_s2() * (1 + 1e-3));
  EXPECT_LE(m.max_jerk, 30.0 * 1.01);
}

TEST(JerkLimitedProfile, AMoveThatReachesTheAccelerationButNotTheSpeedHasNoCruise) {
  // 10 mm at 0.15 m/s, 1.5 m/s², 30 m/s³: v·T_a(v) = 22.5 mm > 10 mm, and the quadratic's peak
  // ≥ a²/j, so the acceleration holds at 1.5 m/s² for a while and the speed peaks below 0.15.
  const JerkLimitedProfile p(0.150, 0.160, {0.15, 1.5, 30.0});
  const double r = 1.5 * 1.5 / 30.0;
  const double vp = 0.5 * (-r + std::sqrt(r * r + 4 * 1.5 * 0.010));
  ASSERT_GE(vp, r);
  EXPECT_NEAR(p.peak_speed_m_s(), vp, 1e-12);
  EXPECT_DOUBLE_EQ(p.peak_accel_m_s2(), 1.5);
  EXPECT_NEAR(p.duration_s(), 2 * (vp / 1.5 + 1.5 / 30.0), 1e-12);
  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, vp * (1 + 1e-6));
  EXPECT_LE(m.max_accel, 1.5 * (1 + 1e-3));
  EXPECT_LE(m.max_jerk, 30.0 * 1.01);
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.160);
}

TEST(JerkLimitedProfile, AnInfiniteJerkIsTheTrapezoid) {
  const JerkLimitedProfile p(0.100, 0.200, {0.05, 0.5, kInf});  // 100 mm at 50 mm/s, 0.5 m/s²
  // 0.1 s to speed (2.5 mm), 1.9 s cruising (95 mm), 0.1 s to stop (2.5 mm).
  EXPECT_NEAR(p.duration_s(), 2.1, 1e-12);
  EXPECT_NEAR(p.position(0.1), 0.1025, 1e-12);
  EXPECT_NEAR(p.position(0.05), 0.100 + 0.5 * 0.5 * 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(p.position(1.05), 0.150, 1e-12);
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.200);
  EXPECT_EQ(p.at(0.05).jerk_m_s3, 0.0);  // the steps of a trapezoid's acceleration have no finite jerk
  EXPECT_DOUBLE_EQ(p.at(0.05).accel_m_s2, 0.5);
  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, 0.05 * (1 + 1e-6));
  EXPECT_LE(m.max_accel, 0.5 * 1.01);
  // A short one is the triangle: peak √(a·d).
  const JerkLimitedProfile t(0.150, 0.149, {0.05, 0.5, kInf});
  EXPECT_NEAR(t.peak_speed_m_s(), std::sqrt(0.5 * 0.001), 1e-12);
  EXPECT_NEAR(t.duration_s(), 2.0 * std::sqrt(0.001 / 0.5), 1e-12);
  for (double s : {0.0, 0.01, 0.03, 0.0447}) {
    EXPECT_TRUE(std::isfinite(t.at(s).accel_m_s2) && std::isfinite(t.at(s).jerk_m_s3)) << s;
  }
}

TEST(JerkLimitedProfile, NoDistanceIsAMoveAlreadyOver) {
  const JerkLimitedProfile p(0.120, 0.120, {0.05, 0.5, 10.0});
  EXPECT_EQ(p.duration_s(), 0.0);
  EXPECT_EQ(p.position(0.0), 0.120);
  EXPECT_EQ(p.position(1.0), 0.120);
  EXPECT_EQ(p.velocity(0.5), 0.0);
  EXPECT_EQ(p.at(0.5).accel_m_s2, 0.0);
}

}  // namespace
}  // namespace hsa::control
