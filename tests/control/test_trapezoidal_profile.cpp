// The point-to-point profile: it ends at rest on the target, and its speed and acceleration,
// measured by finite differences of the positions it gives, stay within their bounds.
#include "control/trapezoidal_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hsa::control {
namespace {

// Largest |speed| and |acceleration| seen by differencing position() on a fine grid, and whether
// position() and velocity() agree.
struct Measured {
  double max_speed = 0.0;
  double max_accel = 0.0;
  double max_velocity_mismatch = 0.0;
};

Measured measure(const TrapezoidalProfile& p) {
  constexpr double dt = 1e-5;
  Measured m;
  double v_prev = 0.0;
  for (double t = 0.0; t <= p.duration_s() + 0.01; t += dt) {
    const double v = (p.position(t + dt) - p.position(t)) / dt;
    m.max_speed = std::max(m.max_speed, std::abs(v));
    if (t > 0.0) m.max_accel = std::max(m.max_accel, std::abs(v - v_prev) / dt);
    m.max_velocity_mismatch = std::max(m.max_velocity_mismatch, std::abs(p.velocity(t + 0.5 * dt) - v));
    v_prev = v;
  }
  return m;
}

TEST(TrapezoidalProfile, ALongMoveCruisesAtTheSpeedAndEndsOnTheTarget) {
  const TrapezoidalProfile p(0.100, 0.200, 0.05, 0.5);  // 100 mm at 50 mm/s, 0.5 m/s²
  // 0.1 s to speed (2.5 mm), 1.9 s cruising (95 mm), 0.1 s to stop (2.5 mm).
  EXPECT_NEAR(p.duration_s(), 2.1, 1e-12);
  EXPECT_DOUBLE_EQ(p.peak_speed_m_s(), 0.05);
  EXPECT_DOUBLE_EQ(p.position(0.0), 0.100);
  EXPECT_NEAR(p.position(0.1), 0.1025, 1e-12);
  EXPECT_NEAR(p.position(1.05), 0.150, 1e-12);  // the middle of a symmetric move
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.200);
  EXPECT_DOUBLE_EQ(p.position(10.0), 0.200);
  EXPECT_DOUBLE_EQ(p.velocity(10.0), 0.0);
  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, 0.05 * (1 + 1e-6));
  EXPECT_LE(m.max_accel, 0.5 * 1.01);  // finite differences at the corners
  EXPECT_LT(m.max_velocity_mismatch, 1e-4);
}

TEST(TrapezoidalProfile, AShortMoveIsATriangleBelowTheSpeed) {
  const TrapezoidalProfile p(0.150, 0.149, 0.05, 0.5);  // 1 mm down: peak √(0.5·0.001) ≈ 22 mm/s
  EXPECT_NEAR(p.peak_speed_m_s(), std::sqrt(0.5 * 0.001), 1e-12);
  EXPECT_NEAR(p.duration_s(), 2.0 * std::sqrt(0.001 / 0.5), 1e-12);
  EXPECT_LT(p.velocity(0.01), 0.0);  // downwards
  EXPECT_NEAR(p.position(p.duration_s() / 2), 0.1495, 1e-12);
  EXPECT_DOUBLE_EQ(p.position(p.duration_s()), 0.149);
  const Measured m = measure(p);
  EXPECT_LE(m.max_speed, p.peak_speed_m_s() * (1 + 1e-6));
  EXPECT_LE(m.max_accel, 0.5 * 1.01);
}

TEST(TrapezoidalProfile, NoDistanceIsAMoveAlreadyOver) {
  const TrapezoidalProfile p(0.120, 0.120, 0.05, 0.5);
  EXPECT_EQ(p.duration_s(), 0.0);
  EXPECT_EQ(p.position(0.0), 0.120);
  EXPECT_EQ(p.position(1.0), 0.120);
  EXPECT_EQ(p.velocity(0.5), 0.0);
}

}  // namespace
}  // namespace hsa::control
