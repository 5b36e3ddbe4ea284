// A move bounded by what the plant can follow in the direction it travels
// (SupervisorParams::capability, from the axis's plant-set file): a speed or an acceleration over
// that direction's limit is refused naming the direction, one asked for as 0 (the axis's) is slowed
// to the direction's limit instead, and neither is ever a fault. Without a capability the axis's
// own bounds are the only ones, as before.
//
// The figures: the simulated rig at 0 kg (docs/plant-set.md), margin 0.7: extending 0.119 m/s and
// 8.26 m/s², retracting 0.1442 m/s and 8.47 m/s². The axis's own bounds sit between the two
// directions' (0.14 m/s, 8.4 m/s²), which a checked configuration refuses
// (daemon/config/capability_check.hpp) but the supervisor does not rely on: it keeps each move
// within its direction whatever its parameters say.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "daemon/supervisor/axis_supervisor.hpp"
#include "tests/daemon/supervisor_test_params.hpp"

namespace hsa::daemon {
namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr std::int64_t kPeriod = test::kSupervisorPeriodNs;
constexpr double kExtendSpeed = 0.7 * 0.170, kExtendAccel = 0.7 * 11.8;
constexpr double kRetractSpeed = 0.7 * 0.206, kRetractAccel = 0.7 * 12.1;

SupervisorParams params(bool with_capability = true) {
  SupervisorParams p = test::short_supervisor_params();
  p.encoder_jump_max_m = 1.0;  // the rod stays put here; nothing about jumps is judged
  p.max_speed_m_s = 0.14;
  p.max_accel_m_s2 = 8.4;
  p.max_jerk_m_s3 = 2000.0;  // high enough that both directions reach their accelerations
  if (with_capability) {
    p.capability.extend = {kExtendSpeed, kExtendAccel};
    p.capability.retract = {kRetractSpeed, kRetractAccel};
  }
  return p;
}

// An enabled axis at mid-stroke (150 mm), holding, stepped one cycle at a time.
struct Axis {
  explicit Axis(const SupervisorParams& p) : sup(p) {
    in.position = {0.150, {}, SampleStatus::ok};
    in.pressure_a = {12e5, {}, SampleStatus::ok};
    in.pressure_b = {9e5, {}, SampleStatus::ok};
    in.has_estop = true;
    in.estop = {false, {}, SampleStatus::ok};
    step();
    op.command = {1, CommandKind::enable, ControlMode::position, {}, 0};
    step();
    step();
  }
  Decision step() {
    t += kPeriod;
    in.t_ns = t;
    in.cycle_gap_ns = kPeriod;
    in.position.timestamp = in.pressure_a.timestamp = in.pressure_b.timestamp = in.spool.timestamp =
        in.estop.timestamp = nanoseconds(t);
    return sup.update(in, op);
  }
  // Sends MOVE_TO; true when accepted.
  bool move_to(double target_m, double speed_m_s = 0.0, double accel_m_s2 = 0.0) {
    op.command = {op.command.seq + 1, CommandKind::move_to, ControlMode::position, {target_m, speed_m_s, accel_m_s2}, 0};
    step();
    return sup.last_command().accepted;
  }
  // The largest |velocity| and |acceleration| the move's setpoint reaches until it ends.
  std::pair<double, double> peaks() {
    double v = 0.0, a = 0.0;
    for (Decision d = step(); d.move_under_way; d = step()) {
      v = std::max(v, std::abs(d.velocity_ff_m_s));
      a = std::max(a, std::abs(d.accel_ff_m_s2));
    }
    return {v, a};
  }

  AxisSupervisor sup;
  SupervisorInputs in;
  AxisInputsFromOperator op;
  std::int64_t t = 0;
};

TEST(SupervisorCapability, ASpeedOverTheDirectionsLimitIsRefusedNamingItAndNeverFaults) {
  Axis axis(params());
  ASSERT_EQ(axis.sup.state(), AxisState::enabled);
  // 0.13 m/s is within the axis's 0.14 and retracting's 0.144, over extending's 0.119.
  EXPECT_FALSE(axis.move_to(0.250, 0.13));
  EXPECT_EQ(axis.sup.last_command().refusal, Refusal::speed_over_extend_capability);
  EXPECT_EQ(axis.sup.state(), AxisState::enabled);
  EXPECT_EQ(axis.sup.faults_tripped(), 0u);
  EXPECT_TRUE(axis.move_to(0.050, 0.13));  // the same speed retracting
  EXPECT_NEAR(axis.peaks().first, 0.13, 1e-9);

  // Retracting's limit is the axis's own here; a plant that retracts slower refuses that way.
  SupervisorParams slow_retract = params();
  slow_retract.capability.retract.speed_m_s = 0.1;
  Axis other(slow_retract);
  EXPECT_FALSE(other.move_to(0.050, 0.13));
  EXPECT_EQ(other.sup.last_command().refusal, Refusal::speed_over_retract_capability);
  EXPECT_TRUE(other.move_to(0.250, 0.1));
  EXPECT_EQ(other.sup.state(), AxisState::enabled);
}

TEST(SupervisorCapability, AnAccelerationOverTheDirectionsLimitIsRefusedNamingIt) {
  Axis axis(params());
  // 8.3 m/s² is within the axis's 8.4 and retracting's 8.47, over extending's 8.26.
  EXPECT_FALSE(axis.move_to(0.250, 0.1, 8.3));
  EXPECT_EQ(axis.sup.last_command().refusal, Refusal::accel_over_extend_capability);
  EXPECT_TRUE(axis.move_to(0.050, 0.1, 8.3));

  SupervisorParams weak_retract = params();
  weak_retract.capability.retract.accel_m_s2 = 5.0;
  Axis other(weak_retract);
  EXPECT_FALSE(other.move_to(0.050, 0.1, 8.3));
  EXPECT_EQ(other.sup.last_command().refusal, Refusal::accel_over_retract_capability);
  EXPECT_EQ(other.sup.faults_tripped(), 0u);
}

// Asked for no speed and no acceleration, a move gets the axis's, slowed to what the plant follows
// the way it travels: extending 0.119 m/s and 8.26 m/s², retracting the axis's 0.14 and 8.4.
TEST(SupervisorCapability, AMoveThatAsksForNoneIsSlowedToItsDirectionsLimitNotRefused) {
  Axis axis(params());
  ASSERT_TRUE(axis.move_to(0.280));  // 130 mm: long enough to cruise
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_speed_m_s(), kExtendSpeed);
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_accel_m_s2(), kExtendAccel);
  const auto [v_out, a_out] = axis.peaks();
  EXPECT_LE(v_out, kExtendSpeed * (1 + 1e-9));
  EXPECT_GT(v_out, kExtendSpeed * 0.999);  // it cruised at the limit
  EXPECT_LE(a_out, kExtendAccel * (1 + 1e-9));

  ASSERT_TRUE(axis.move_to(0.020));  // back, retracting: the axis's own bounds are the smaller
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_speed_m_s(), 0.14);
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_accel_m_s2(), 8.4);
  EXPECT_EQ(axis.sup.faults_tripped(), 0u);
}

// No plant set: the axis's bounds alone, whichever way (the moves refused above are accepted, and
// one that asks for none goes at the axis's speed extending too).
TEST(SupervisorCapability, WithoutACapabilityTheAxisBoundsAloneCount) {
  Axis axis(params(false));
  EXPECT_TRUE(axis.move_to(0.250, 0.13, 8.3));
  ASSERT_TRUE(axis.move_to(0.280));
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_speed_m_s(), 0.14);
  EXPECT_DOUBLE_EQ(axis.sup.move().peak_accel_m_s2(), 8.4);
  EXPECT_FALSE(axis.move_to(0.050, 0.15));  // over the axis's own speed, as before
  EXPECT_EQ(axis.sup.last_command().refusal, Refusal::speed_over_limit);
}

// The refusals' texts, which status_t.result_reason and hsactl print (hsad adds the figure): each
// names its direction and the capability's key.
TEST(SupervisorCapability, TheRefusalsNameTheirDirectionAndTheCapabilityKey) {
  EXPECT_EQ(to_string(Refusal::speed_over_extend_capability),
            "speed over what the plant can follow extending, its speed_limit_m_s");
  EXPECT_EQ(to_string(Refusal::speed_over_retract_capability),
            "speed over what the plant can follow retracting, its speed_limit_m_s");
  EXPECT_EQ(to_string(Refusal::accel_over_extend_capability),
            "acceleration over what the plant can follow extending, its acceleration_limit_m_s2");
  EXPECT_EQ(to_string(Refusal::accel_over_retract_capability),
            "acceleration over what the plant can follow retracting, its acceleration_limit_m_s2");
}

}  // namespace
}  // namespace hsa::daemon
