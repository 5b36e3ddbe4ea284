// A streamed setpoint in position mode reaches the loop through the supervisor's limiter
// (control/setpoint_limiter.hpp): within the axis's speed and the moves' acceleration bound,
// without a bump on the first sample (from the held position, or from a move it takes over), with
// the limiter's velocity and acceleration as the feed-forward, and counted when it is slowed. An
// axis without finite bounds passes the stream on as it is.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "daemon/supervisor/axis_supervisor.hpp"
#include "tests/daemon/supervisor_test_params.hpp"

namespace hsa::daemon {
namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr std::int64_t kPeriod = test::kSupervisorPeriodNs;
constexpr double kT = kPeriod * 1e-9;
constexpr double kV = 0.1;
constexpr double kA = 1.0;

SupervisorParams limited_params() {
  SupervisorParams p = test::short_supervisor_params();
  p.max_speed_m_s = kV;
  p.max_accel_m_s2 = kA;
  p.setpoint_timeout_ns = 100 * kPeriod;  // a stream every cycle never times out
  return p;
}

io::AnalogSample ok_sample(double value) { return {value, {}, SampleStatus::ok}; }

// A healthy axis at 150 mm, stepped one cycle at a time (the rod does not move: only the
// setpoint is judged here).
struct Bench {
  explicit Bench(SupervisorParams p = limited_params()) : sup(p) {
    in.position = ok_sample(0.150);
    in.pressure_a = ok_sample(12e5);
    in.pressure_b = ok_sample(9e5);
    in.has_estop = true;
    in.estop = {false, {}, SampleStatus::ok};
    step();
    op.command = {op.command.seq + 1, CommandKind::enable, ControlMode::position, {}, 0};
    step();
  }
  Decision step() {
    t += kPeriod;
    in.t_ns = t;
    in.cycle_gap_ns = kPeriod;
    in.position.timestamp = in.pressure_a.timestamp = in.pressure_b.timestamp = in.spool.timestamp =
        in.estop.timestamp = nanoseconds(t);
    last = sup.update(in, op);
    return last;
  }
  Decision setpoint(double target, double velocity_m_s = 0.0) {
    op.setpoint.seq += 1;
    op.setpoint.target = target;
    op.setpoint.velocity_m_s = velocity_m_s;
    return step();
  }
  AxisSupervisor sup;
  SupervisorInputs in;
  AxisInputsFromOperator op;
  Decision last;
  std::int64_t t = 0;
};

TEST(SupervisorStreamLimiter, AStreamedStepIsFollowedWithinTheBoundsFromTheHeldPosition) {
  Bench b;
  ASSERT_TRUE(b.sup.limiting_streams());
  ASSERT_EQ(b.sup.state(), AxisState::enabled);
  ASSERT_TRUE(b.step().holding);  // at 150 mm
  double previous = 0.150, previous_speed = 0.0, top_speed = 0.0, top_accel = 0.0;
  Decision d;
  for (int k = 0; k < 20'000; ++k) {  // 2 s: a 100 mm step takes 1.1 s at 0.1 m/s and 1 m/s²
    d = b.setpoint(0.250);
    ASSERT_TRUE(d.drive);
    ASSERT_FALSE(d.holding);
    const double speed = (d.rod_setpoint_m - previous) / kT;  // finite differences, not the FF
    top_speed = std::max(top_speed, std::abs(speed));
    top_accel = std::max(top_accel, std::abs(speed - previous_speed) / kT);
    if (k == 0) {
      EXPECT_NEAR(d.rod_setpoint_m, 0.150, kA * kT * kT);  // no bump on the first sample
    }
    EXPECT_NEAR(d.velocity_ff_m_s, b.sup.stream_limiter().velocity_m_s(), 0.0);
    EXPECT_LE(std::abs(d.accel_ff_m_s2), kA * (1 + 1e-9));  // the limiter's, low-passed: within its bound
    previous = d.rod_setpoint_m;
    previous_speed = speed;
  }
  EXPECT_LE(top_speed, kV * (1 + 1e-9));
  EXPECT_GT(top_speed, kV * 0.999);  // it cruised at the bound: slowed, not stopped
  EXPECT_LE(top_accel, kA * (1 + 1e-6));
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.250);
  EXPECT_EQ(d.velocity_ff_m_s, 0.0);
  // Slowed for about the time it lagged more than kSlowedSetpointM: most of the 1.1 s.
  const double limited_s = static_cast<double>(b.sup.setpoint_cycles_limited()) * kT;
  EXPECT_GT(limited_s, 0.9);
  EXPECT_LT(limited_s, 1.1);
}

// While the limiter lags the stream it plans the setpoint's path, as a move does, and the Decision
// says so (the PI holds its integrator); once it has caught up, or for a stream it can follow, not.
TEST(SupervisorStreamLimiter, TheSetpointIsPlannedExactlyWhileTheLimiterLagsTheStream) {
  Bench b;
  b.step();
  std::uint64_t planned = 0;
  Decision d;
  for (int k = 0; k < 20'000; ++k) {
    d = b.setpoint(0.250);
    EXPECT_EQ(d.setpoint_planned, std::abs(b.sup.stream_limiter().lag_m()) > kSlowedSetpointM) << k;
    EXPECT_FALSE(d.move_under_way);
    planned += d.setpoint_planned ? 1 : 0;
  }
  EXPECT_EQ(planned, b.sup.setpoint_cycles_limited());
  EXPECT_GT(planned, 9'000u);  // most of the 1.1 s step
  EXPECT_FALSE(d.setpoint_planned);  // arrived
  // A slow ramp the limiter follows within a stair: never planned.
  for (int k = 1; k <= 5'000; ++k) EXPECT_FALSE(b.setpoint(0.250 - 1e-6 * k).setpoint_planned) << k;
}

TEST(SupervisorStreamLimiter, AStreamWithinTheBoundsIsFollowedAndNotCountedAsSlowed) {
  Bench b;
  b.step();
  // A 5 mm, 1 Hz sine: 31 mm/s and 0.2 m/s² at most, sent with its velocity.
  const double w = 2 * M_PI;
  double worst = 0.0;
  for (int k = 0; k < 20'000; ++k) {
    const double t = k * kT;
    const Decision d = b.setpoint(0.150 + 0.005 * std::sin(w * t), 0.005 * w * std::cos(w * t));
    if (t > 0.2) worst = std::max(worst, std::abs(d.rod_setpoint_m - (0.150 + 0.005 * std::sin(w * t))));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(b.sup.setpoint_cycles_limited(), 0u);
}

// A stream of positions alone at 1 kHz (hsactl sine) is a staircase at the 10 kHz cycle: the
// limiter meets each stair at its full acceleration, and the feed-forward gets that averaged
// (kStreamAccelFilterS), which is the sine's acceleration again; the position is followed closely.
TEST(SupervisorStreamLimiter, APositionStreamAt1kHzIsFollowedWithASmoothAccelerationFeedForward) {
  Bench b;
  b.step();
  const double w = 2 * M_PI * 1.0, ampl = 0.01;  // 10 mm at 1 Hz: 63 mm/s, 0.39 m/s²
  double worst_position = 0.0, worst_accel_ff = 0.0, raw_accel = 0.0;
  std::uint64_t limited_at_start = 0;
  for (int k = 0; k < 30'000; ++k) {
    const double t = k * kT;
    const Decision d = k % 10 == 0 ? b.setpoint(0.150 + ampl * std::sin(w * t)) : b.step();
    if (k == 10'000) limited_at_start = b.sup.setpoint_cycles_limited();
    if (t < 1.0) continue;  // past the start, where the sine begins at full speed from rest
    worst_position = std::max(worst_position, std::abs(d.rod_setpoint_m - (0.150 + ampl * std::sin(w * t))));
    worst_accel_ff = std::max(worst_accel_ff, std::abs(d.accel_ff_m_s2 + ampl * w * w * std::sin(w * t)));
    raw_accel = std::max(raw_accel, std::abs(b.sup.stream_limiter().accel_m_s2()));
  }
  std::printf("10 mm 1 Hz at 1 kHz: |setpoint - sine| <= %.4f mm, |accel FF - sine's| <= %.3f m/s^2 "
              "(the limiter's own reaches %.2f)\n", worst_position * 1e3, worst_accel_ff, raw_accel);
  EXPECT_LT(worst_position, 0.1e-3);  // within a stair (63 µm) and a little
  EXPECT_GT(raw_accel, 0.9 * kA);     // what the filter is for
  EXPECT_LT(worst_accel_ff, 0.2);     // half the sine's peak acceleration at most
  EXPECT_GT(limited_at_start, 0u);  // catching up with a sine that starts at full speed is slowing
  EXPECT_EQ(b.sup.setpoint_cycles_limited(), limited_at_start);  // following it is not
}

TEST(SupervisorStreamLimiter, AStreamTakingOverAMoveGoesOnFromItsSetpointAndVelocity) {
  Bench b;
  b.step();
  b.op.command = {b.op.command.seq + 1, CommandKind::move_to, ControlMode::position, {0.250, 0.0, 0.0}, 0};
  for (int k = 0; k < 3000; ++k) b.step();  // 0.3 s into the move: cruising
  const Decision moving = b.last;
  ASSERT_TRUE(moving.move_under_way);
  ASSERT_GT(moving.velocity_ff_m_s, 0.05);
  const Decision d = b.setpoint(0.100);  // back the other way
  EXPECT_NEAR(d.rod_setpoint_m, moving.rod_setpoint_m, kV * kT * 1.01);
  EXPECT_NEAR(d.velocity_ff_m_s, moving.velocity_ff_m_s, kA * kT * 1.01);  // no velocity step
  EXPECT_FALSE(d.move_under_way);
}

TEST(SupervisorStreamLimiter, WithoutFiniteBoundsTheStreamGoesToTheLoopAsItIs) {
  SupervisorParams p = limited_params();
  p.max_speed_m_s = std::numeric_limits<double>::infinity();
  p.max_accel_m_s2 = std::numeric_limits<double>::infinity();
  Bench b(p);
  EXPECT_FALSE(b.sup.limiting_streams());
  b.step();
  const Decision d = b.setpoint(0.250, 0.3);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.250);
  EXPECT_DOUBLE_EQ(d.velocity_ff_m_s, 0.3);
}

TEST(SupervisorStreamLimiter, AStreamBeyondTheSoftLimitStopsInsideItWithoutOvershoot) {
  Bench b;
  b.step();
  double highest = 0.0;
  for (int k = 0; k < 30'000; ++k) highest = std::max(highest, b.setpoint(0.5).rod_setpoint_m);
  const double high = limited_params().soft_limit_high_m - kSoftLimitSetpointMarginM;
  EXPECT_LE(highest, high);
  EXPECT_DOUBLE_EQ(b.last.rod_setpoint_m, high);
}

}  // namespace
}  // namespace hsa::daemon
