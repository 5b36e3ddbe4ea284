// The supervisor's excitation (excite): the sequence drives the rod setpoint level by level, the
// axis holds the working point at its end, every listed event ends it, and what it refuses is
// refused with the reason and changes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "control/excitation_sequence.hpp"
#include "daemon/supervisor/axis_supervisor.hpp"
#include "tests/daemon/supervisor_test_params.hpp"

namespace hsa::daemon {
namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr std::int64_t kPeriod = test::kSupervisorPeriodNs;  // 100 µs

io::AnalogSample ok_sample(double value) { return {value, {}, SampleStatus::ok}; }

// A healthy axis at 150 mm, stepped one cycle at a time.
struct Bench {
  Bench() : sup(test::short_supervisor_params()) {
    in.position = ok_sample(0.150);
    in.pressure_a = ok_sample(12e5);
    in.pressure_b = ok_sample(9e5);
    in.has_estop = true;
    in.estop = {false, {}, SampleStatus::ok};
  }
  Decision step() {
    t += kPeriod;
    in.t_ns = t;
    in.cycle_gap_ns = kPeriod;
    in.position.timestamp = nanoseconds(t);
    in.pressure_a.timestamp = nanoseconds(t);
    in.pressure_b.timestamp = nanoseconds(t);
    in.estop.timestamp = nanoseconds(t);
    last = sup.update(in, op);
    return last;
  }
  Decision command(CommandKind kind, ControlMode mode = ControlMode::position) {
    op.command = AxisCommand{};
    op.command.seq = ++seq;
    op.command.kind = kind;
    op.command.mode = mode;
    return step();
  }
  Decision excite(const ExcitationRequest& r) {
    op.command = AxisCommand{};
    op.command.seq = ++seq;
    op.command.kind = CommandKind::excite;
    op.command.excite = r;
    return step();
  }
  Decision setpoint(double target) {
    op.setpoint.seq += 1;
    op.setpoint.target = target;
    return step();
  }
  void enable() {
    step();
    ASSERT_EQ(sup.state(), AxisState::disabled);
    ASSERT_EQ(command(CommandKind::enable).state, AxisState::enabled);
  }

  AxisSupervisor sup;
  SupervisorInputs in;
  AxisInputsFromOperator op;
  Decision last;
  std::int64_t t = 0;
  std::uint64_t seq = 0;
};

// ±1 mm PRMS around 150 mm, a level every 10 ms (100 cycles), for 0.2 s.
ExcitationRequest request(double working_point_m = 0.150) {
  return {.working_point_m = working_point_m,
          .kind = control::ExcitationKind::prms,
          .amplitude_m = 1e-3,
          .switching_time_s = 0.01,
          .levels = 5,
          .seed = 3,
          .duration_s = 0.2,
          .kp_per_m = 200.0};
}

constexpr int kRunCycles = 2000;  // 0.2 s

TEST(SupervisorExcitation, TheSequenceDrivesTheSetpointLevelByLevel) {
  Bench b;
  b.enable();
  Decision d = b.excite(request());
  ASSERT_TRUE(b.sup.last_command().accepted);
  // The same seed sampled every cycle, as the offline model samples it every loop period: the
  // levels and the switching instants must be these.
  control::ExcitationSequence expected({.kind = control::ExcitationKind::prms,
                                        .amplitude = 1e-3,
                                        .switching_time_s = 0.01,
                                        .levels = 5,
                                        .seed = 3,
                                        .sample_period_s = kPeriod * 1e-9});
  std::set<long> levels_seen;
  for (int k = 0; k < kRunCycles; ++k) {
    ASSERT_TRUE(d.drive);
    ASSERT_TRUE(d.exciting) << "cycle " << k;
    ASSERT_FALSE(d.holding);
    ASSERT_EQ(d.excite_kp_per_m, 200.0);
    ASSERT_EQ(d.velocity_ff_m_s, 0.0);
    const double offset = expected.next();
    ASSERT_NEAR(d.rod_setpoint_m, 0.150 + offset, 1e-12) << "cycle " << k;
    levels_seen.insert(std::lround(offset * 1e4));
    EXPECT_TRUE(b.sup.exciting());
    d = b.step();
  }
  EXPECT_GE(levels_seen.size(), 3u);  // it did switch, over several of the 5 levels
  // Its duration is over: the axis holds the working point, as after setpoint silence, and keeps
  // holding it (not the rod) however long no setpoint comes.
  EXPECT_FALSE(d.exciting);
  EXPECT_FALSE(b.sup.exciting());
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.150);
  b.in.position.value = 0.1504;
  for (int k = 0; k < 500; ++k) d = b.step();
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.150);
  EXPECT_EQ(d.state, AxisState::enabled);
  // The next setpoint is followed again.
  EXPECT_DOUBLE_EQ(b.setpoint(0.155).rod_setpoint_m, 0.155);
}

TEST(SupervisorExcitation, APrbsTakesOnlyPlusAndMinusTheAmplitude) {
  Bench b;
  b.enable();
  ExcitationRequest r = request();
  r.kind = control::ExcitationKind::prbs;
  Decision d = b.excite(r);
  std::set<double> values;
  for (int k = 0; k < kRunCycles; ++k, d = b.step()) values.insert(d.rod_setpoint_m - 0.150);
  ASSERT_EQ(values.size(), 2u);
  EXPECT_NEAR(*values.begin(), -1e-3, 1e-12);
  EXPECT_NEAR(*values.rbegin(), 1e-3, 1e-12);
}

// Runs an excitation for 50 cycles, then `end` (which returns the decision of its cycle).
template <class End>
Decision end_by(Bench& b, End end) {
  b.enable();
  b.excite(request());
  for (int k = 0; k < 50; ++k) EXPECT_TRUE(b.step().exciting);
  const Decision d = end(b);
  EXPECT_FALSE(d.exciting);
  EXPECT_FALSE(b.sup.exciting());
  return d;
}

TEST(SupervisorExcitation, AStreamedSetpointEndsItAndIsFollowed) {
  Bench b;
  const Decision d = end_by(b, [](Bench& b) { return b.setpoint(0.140); });
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.140);
  EXPECT_FALSE(b.step().exciting);  // it does not come back
}

TEST(SupervisorExcitation, AMoveEndsItAndStartsFromTheExcitationsSetpoint) {
  Bench b;
  double before = 0.0;
  Decision d = end_by(b, [&](Bench& b) {
    before = b.last.rod_setpoint_m;
    b.op.command = AxisCommand{};
    b.op.command.seq = ++b.seq;
    b.op.command.kind = CommandKind::move_to;
    b.op.command.move = {.target_m = 0.160, .speed_m_s = 0.05, .accel_m_s2 = 0.5};
    return b.step();
  });
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_NEAR(d.rod_setpoint_m, before, 1e-6);  // no jump
  for (int k = 0; k < 5000; ++k) d = b.step();
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.160);
}

TEST(SupervisorExcitation, AModeCommandEndsItHoldingTheWorkingPoint) {
  Bench b;
  const Decision d = end_by(b, [](Bench& b) { return b.command(CommandKind::set_mode, ControlMode::position); });
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.150);
  Bench open;
  const Decision o = end_by(open, [](Bench& b) { return b.command(CommandKind::set_mode, ControlMode::open_loop); });
  EXPECT_EQ(o.mode, ControlMode::open_loop);
  EXPECT_EQ(o.opening, 0.0);
}

TEST(SupervisorExcitation, ADisableEndsItAndTheNextEnableDoesNotResumeIt) {
  Bench b;
  const Decision d = end_by(b, [](Bench& b) { return b.command(CommandKind::disable); });
  EXPECT_FALSE(d.drive);
  b.command(CommandKind::enable);
  EXPECT_FALSE(b.step().exciting);
}

TEST(SupervisorExcitation, AFaultEndsItAndItsFaultsStayArmedMeanwhile) {
  Bench b;
  const Decision d = end_by(b, [](Bench& b) {
    b.in.following_error_m = 0.02;  // over the 10 mm bound, for the streak
    Decision last;
    for (int k = 0; k < 5; ++k) last = b.step();
    return last;
  });
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::following_error);
  b.in.following_error_m = 0.0;
  b.step();
  b.command(CommandKind::reset);
  b.command(CommandKind::enable);
  EXPECT_FALSE(b.step().exciting);
}

TEST(SupervisorExcitation, AnotherExcitationReplacesItAsANewRun) {
  Bench b;
  b.enable();
  const Decision first = b.excite(request());
  b.step();
  const Decision second = b.excite(request(0.160));
  EXPECT_TRUE(second.exciting);
  EXPECT_GT(second.excitation, first.excitation);  // the loop starts it afresh
  EXPECT_NEAR(second.rod_setpoint_m, 0.160, 1e-3 + 1e-12);
}

TEST(SupervisorExcitation, StopExcitationHoldsTheWorkingPoint) {
  Bench b;
  b.enable();
  b.excite(request(0.152));
  b.step();
  b.sup.stop_excitation();
  const Decision d = b.step();
  EXPECT_FALSE(d.exciting);
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.152);
}

TEST(SupervisorExcitation, IsRefusedWithItsReasonAndARefusalChangesNothing) {
  Bench b;
  b.step();
  b.excite(request());
  EXPECT_FALSE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::not_enabled);
  b.enable();
  // Soft limits [5, 299] mm: 298.5 ± 1 mm leaves them.
  b.excite(request(0.2985));
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::excitation_outside_limits);
  EXPECT_FALSE(b.last.exciting);
  ExcitationRequest no_levels = request();
  no_levels.levels = 1;
  b.excite(no_levels);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::excitation_invalid);
  // A running excitation goes on through a refused one.
  b.excite(request());
  ASSERT_TRUE(b.sup.last_command().accepted);
  const std::uint64_t run = b.last.excitation;
  b.excite(request(0.004));
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::excitation_outside_limits);
  EXPECT_TRUE(b.last.exciting);
  EXPECT_EQ(b.last.excitation, run);
  b.command(CommandKind::set_mode, ControlMode::open_loop);
  b.excite(request());
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::not_position_mode);
  EXPECT_EQ(b.sup.state(), AxisState::enabled);
  EXPECT_FALSE(b.step().exciting);
}

}  // namespace
}  // namespace hsa::daemon
