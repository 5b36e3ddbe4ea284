// The axis state machine alone: every transition, every fault class (safe in the same update,
// latched, reset refused while the cause is present, reset accepted after), setpoint silence.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "daemon/supervisor/axis_supervisor.hpp"
#include "tests/daemon/supervisor_test_params.hpp"

namespace hsa::daemon {
namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr std::int64_t kPeriod = test::kSupervisorPeriodNs;

SupervisorParams test_params(double encoder_jump_max_m = 0.005) {
  SupervisorParams p = test::short_supervisor_params();
  p.encoder_jump_max_m = encoder_jump_max_m;
  return p;
}

io::AnalogSample ok_sample(double value) { return {value, {}, SampleStatus::ok}; }

// A healthy axis at mid-stroke, stepped one cycle at a time.
struct Bench {
  explicit Bench(SupervisorParams p = test_params()) : params(p), sup(p) {
    in.position = ok_sample(0.150);
    in.pressure_a = ok_sample(12e5);
    in.pressure_b = ok_sample(9e5);
    in.has_estop = true;
    in.estop = {false, {}, SampleStatus::ok};
  }

  Decision step() {
    t += next_gap > 0 ? next_gap : kPeriod;
    in.t_ns = t;
    in.cycle_gap_ns = next_gap > 0 ? next_gap : kPeriod;
    next_gap = 0;
    if (fresh_encoder) in.position.timestamp = nanoseconds(t);
    if (fresh_pressure_a) in.pressure_a.timestamp = nanoseconds(t);
    if (frozen != FaultSignal::pressure_b) in.pressure_b.timestamp = nanoseconds(t);
    if (frozen != FaultSignal::spool) in.spool.timestamp = nanoseconds(t);
    if (frozen != FaultSignal::estop) in.estop.timestamp = nanoseconds(t);
    last = sup.update(in, op);
    return last;
  }
  Decision command(CommandKind kind, ControlMode mode = ControlMode::position) {
    op.command = {op.command.seq + 1, kind, mode, {}, 0};
    return step();
  }
  Decision move_to(double target_m, double speed_m_s = 0.0, double accel_m_s2 = 0.0) {
    op.command = {op.command.seq + 1, CommandKind::move_to, op.command.mode, {target_m, speed_m_s, accel_m_s2}, 0};
    return step();
  }
  Decision setpoint(double target) {
    op.setpoint.seq += 1;
    op.setpoint.target = target;
    return step();
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) step();
  }
  // Moves the rod 1 mm per cycle, slower than a jump.
  void glide_to(double x) {
    while (std::abs(in.position.value - x) > 1e-3) {
      in.position.value += in.position.value < x ? 1e-3 : -1e-3;
      step();
    }
    in.position.value = x;
    step();
  }
  // INIT → DISABLED → ENABLED.
  void enable() {
    step();
    ASSERT_EQ(sup.state(), AxisState::disabled);
    const Decision d = command(CommandKind::enable);
    ASSERT_EQ(d.state, AxisState::enabled);
    ASSERT_TRUE(d.drive);
  }

  SupervisorParams params;
  AxisSupervisor sup;
  SupervisorInputs in;
  AxisInputsFromOperator op;
  Decision last;
  std::int64_t t = 0;
  bool fresh_encoder = true;
  bool fresh_pressure_a = true;
  FaultSignal frozen = FaultSignal::none;  // this input's timestamp stops advancing
  std::int64_t next_gap = 0;  // > 0: the next step comes this long after the last one
};

TEST(AxisSupervisor, StartsInInitThenDisabledWithValveSafe) {
  Bench b;
  EXPECT_EQ(b.sup.state(), AxisState::init);
  const Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::disabled);
  EXPECT_FALSE(d.drive);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::none);
}

TEST(AxisSupervisor, FaultyInputsAtStartGoFromInitToFault) {
  Bench b;
  b.in.pressure_a.status = SampleStatus::out_of_range;  // delivered, and bad
  const Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::sensor_not_ok);
  EXPECT_EQ(b.sup.fault().signal, FaultSignal::pressure_a);
}

// A bus driver has nothing to hand over before its first poll: INIT waits for every input's first
// sample instead of latching "e-stop disconnected", and judges them from then on.
TEST(AxisSupervisor, InitWaitsForTheFirstSampleOfEveryInput) {
  SupervisorParams p = test_params();
  p.startup_timeout_ns = 1000 * kPeriod;  // 100 ms
  Bench b(p);
  b.in.estop.status = SampleStatus::disconnected;
  b.in.pressure_b.status = SampleStatus::disconnected;
  b.run(500);
  EXPECT_EQ(b.sup.state(), AxisState::init);
  EXPECT_FALSE(b.last.drive);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::none);
  EXPECT_EQ(b.sup.active_faults(), 0u);
  b.command(CommandKind::enable);
  EXPECT_FALSE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::starting);
  EXPECT_EQ(b.sup.state(), AxisState::init);

  b.in.estop.status = SampleStatus::ok;
  b.step();
  EXPECT_EQ(b.sup.state(), AxisState::init);  // pressure B still has nothing
  b.in.pressure_b.status = SampleStatus::ok;
  b.step();
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
  b.command(CommandKind::enable);
  EXPECT_EQ(b.sup.state(), AxisState::enabled);
}

TEST(AxisSupervisor, AnInputSilentPastTheStartupTimeoutFaultsNamingIt) {
  SupervisorParams p = test_params();
  p.startup_timeout_ns = 1000 * kPeriod;  // 100 ms
  Bench b(p);
  b.in.estop.status = SampleStatus::disconnected;
  b.run(1000);  // the first update is t = 0 of the wait: 999 periods waited
  EXPECT_EQ(b.sup.state(), AxisState::init);
  const Decision d = b.step();
  EXPECT_TRUE(d.tripped);
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_FALSE(d.drive);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::inputs_not_ready);
  EXPECT_EQ(b.sup.fault().signal, FaultSignal::estop);
  EXPECT_EQ(describe(b.sup.fault()), "no first sample from e-stop within 0.1 s of start-up");
  // Still silent: the reset names the cause, an unreadable e-stop.
  b.command(CommandKind::reset);
  EXPECT_FALSE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.last_command().blocking, FaultReason::estop);
  // Once it reads released, the reset goes through.
  b.in.estop.status = SampleStatus::ok;
  b.step();
  b.command(CommandKind::reset);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
}

// While INIT waits, what needs no input is still judged: an asserted e-stop, a driver error.
TEST(AxisSupervisor, InitStillJudgesAnAssertedEstopAndADriverError) {
  Bench pressed;
  pressed.in.pressure_a.status = SampleStatus::disconnected;
  pressed.in.estop.value = true;
  EXPECT_EQ(pressed.step().state, AxisState::estop);
  EXPECT_EQ(pressed.sup.fault().reason, FaultReason::estop);

  Bench failed;
  failed.in.pressure_a.status = SampleStatus::disconnected;
  failed.in.executive.driver_error = true;
  EXPECT_EQ(failed.step().state, AxisState::fault);
  EXPECT_EQ(failed.sup.fault().reason, FaultReason::driver_error);
}

TEST(AxisSupervisor, EnableActivatesTheLoopsAndDisableStopsThem) {
  Bench b;
  b.step();
  Decision d = b.command(CommandKind::enable);
  EXPECT_EQ(d.state, AxisState::enabled);
  EXPECT_TRUE(d.drive);
  EXPECT_TRUE(d.activate);
  d = b.step();
  EXPECT_FALSE(d.activate);  // only once, on the transition
  d = b.command(CommandKind::enable);  // already enabled: accepted, no re-activation
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_FALSE(d.activate);
  d = b.command(CommandKind::disable);
  EXPECT_EQ(d.state, AxisState::disabled);
  EXPECT_FALSE(d.drive);
  EXPECT_TRUE(b.sup.last_command().accepted);
}

TEST(AxisSupervisor, ACommandIsHandledOncePerSequenceNumber) {
  Bench b;
  b.step();
  b.in.executive.driver_error = true;
  b.step();
  ASSERT_EQ(b.sup.state(), AxisState::fault);
  b.command(CommandKind::enable);
  b.run(10);  // the same command struct, ten more cycles
  EXPECT_EQ(b.sup.commands_refused(), 1u);
  EXPECT_EQ(b.sup.last_command().seq, b.op.command.seq);
}

TEST(AxisSupervisor, EnableWhileFaultIsRefusedWithResetFirst) {
  Bench b;
  b.enable();
  b.in.executive.driver_error = true;
  b.step();
  b.in.executive.driver_error = false;
  const Decision d = b.command(CommandKind::enable);
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_FALSE(d.drive);
  EXPECT_FALSE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::reset_first);
  EXPECT_EQ(to_string(Refusal::reset_first), "axis in FAULT: reset first");
}

TEST(AxisSupervisor, EnableInTheCycleAFaultTripsIsRefused) {
  Bench b;
  b.step();
  b.in.pressure_b.value = 30e5;
  const Decision d = b.command(CommandKind::enable);
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_FALSE(d.drive);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::reset_first);
}

TEST(AxisSupervisor, DisableInFaultIsHarmlessAndKeepsTheFault) {
  Bench b;
  b.enable();
  b.in.executive.driver_error = true;
  b.step();
  const Decision d = b.command(CommandKind::disable);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(d.state, AxisState::fault);
}

TEST(AxisSupervisor, ResetWithoutFaultIsANoOp) {
  Bench b;
  b.enable();
  const Decision d = b.command(CommandKind::reset);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(d.state, AxisState::enabled);
}

// One fault class: how to cause it, how to clear the cause, what it must report.
struct FaultCase {
  std::string name;
  std::function<void(Bench&)> inject;
  std::function<void(Bench&)> clear;  // empty: the cause ends with the freeze (transient class)
  FaultReason reason;
  FaultSignal signal;
  int cycles_to_trip = 1;  // updates from the first injected one to the trip
};

std::vector<FaultCase> fault_cases() {
  return {
      {"sensor_disconnected",
       [](Bench& b) { b.in.pressure_b.status = SampleStatus::disconnected; },
       [](Bench& b) { b.in.pressure_b.status = SampleStatus::ok; }, FaultReason::sensor_not_ok,
       FaultSignal::pressure_b},
      {"sensor_nan",
       [](Bench& b) { b.in.position.value = std::numeric_limits<double>::quiet_NaN(); },
       [](Bench& b) { b.in.position.value = 0.150; }, FaultReason::sensor_not_ok,
       FaultSignal::position},
      {"spool_out_of_range",
       [](Bench& b) {
         b.in.has_spool = true;
         b.in.spool = {0.0, {}, SampleStatus::out_of_range};
       },
       [](Bench& b) { b.in.spool.status = SampleStatus::ok; }, FaultReason::sensor_not_ok,
       FaultSignal::spool},
      {"encoder_stale", [](Bench& b) { b.fresh_encoder = false; },
       [](Bench& b) { b.fresh_encoder = true; }, FaultReason::encoder_stale,
       FaultSignal::position, 3},
      {"pressure_a_stale", [](Bench& b) { b.fresh_pressure_a = false; },
       [](Bench& b) { b.fresh_pressure_a = true; }, FaultReason::sensor_not_ok,
       FaultSignal::pressure_a, 6},  // the same timestamp for more than 5 periods
      {"blind_time", [](Bench& b) { b.next_gap = 50'000'000; }, nullptr, FaultReason::blind_time,
       FaultSignal::none},
      {"encoder_jump", [](Bench& b) { b.in.position.value += 0.006; }, nullptr,
       FaultReason::encoder_jump, FaultSignal::position},
      {"over_pressure_a", [](Bench& b) { b.in.pressure_a.value = 27.1e5; },
       [](Bench& b) { b.in.pressure_a.value = 20e5; }, FaultReason::over_pressure,
       FaultSignal::pressure_a},
      {"soft_limit_high",
       [](Bench& b) {
         b.glide_to(0.2985);
         b.in.position.value = 0.2995;
       },
       nullptr, FaultReason::soft_limit, FaultSignal::position},  // reset outside: see below
      {"following_error", [](Bench& b) { b.in.following_error_m = -0.011; },
       nullptr, FaultReason::following_error, FaultSignal::position, 5},
      {"current_saturated", [](Bench& b) { b.in.command_saturated = true; }, nullptr,
       FaultReason::current_saturated, FaultSignal::none, 4},
      {"rt_overruns", [](Bench& b) { b.in.executive.overrun_streak = 3; },
       [](Bench& b) { b.in.executive.overrun_streak = 0; }, FaultReason::rt_overruns,
       FaultSignal::none},
      {"driver_error", [](Bench& b) { b.in.executive.driver_error = true; },
       [](Bench& b) { b.in.executive.driver_error = false; }, FaultReason::driver_error,
       FaultSignal::none},
  };
}

TEST(AxisSupervisor, EveryFaultClassIsSafeInTheSameUpdateLatchedAndResettable) {
  for (const FaultCase& c : fault_cases()) {
    SCOPED_TRACE(c.name);
    Bench b;
    b.enable();
    b.setpoint(0.150);
    b.run(2);
    c.inject(b);
    for (int i = 1; i < c.cycles_to_trip; ++i) {
      ASSERT_EQ(b.step().state, AxisState::enabled) << "tripped early, cycle " << i;
    }
    Decision d = b.step();
    EXPECT_EQ(d.state, AxisState::fault);
    EXPECT_TRUE(d.tripped);
    EXPECT_FALSE(d.drive);  // the valve goes safe in this very update
    EXPECT_EQ(b.sup.fault().reason, c.reason);
    EXPECT_EQ(b.sup.fault().signal, c.signal);
    EXPECT_EQ(b.sup.fault().t_ns, b.t);
    EXPECT_EQ(b.sup.faults_tripped(), 1u);

    if (c.clear) {
      d = b.command(CommandKind::reset);
      EXPECT_EQ(d.state, AxisState::fault);
      EXPECT_FALSE(b.sup.last_command().accepted);
      EXPECT_EQ(b.sup.last_command().refusal, Refusal::cause_present);
      EXPECT_EQ(b.sup.last_command().blocking, c.reason);
      c.clear(b);
    }
    d = b.step();  // the cause is gone: still latched
    EXPECT_EQ(d.state, AxisState::fault);
    EXPECT_EQ(b.sup.fault().reason, c.reason);

    d = b.command(CommandKind::reset);
    EXPECT_TRUE(b.sup.last_command().accepted);
    EXPECT_EQ(d.state, AxisState::disabled);
    EXPECT_EQ(b.sup.fault().reason, FaultReason::none);
    d = b.command(CommandKind::enable);
    EXPECT_EQ(d.state, AxisState::enabled);
    EXPECT_TRUE(d.activate);
  }
}

TEST(AxisSupervisor, EnabledOutsideTheSoftLimitsTheAxisOnlyRecovers) {
  Bench b;
  b.enable();
  b.setpoint(0.150);
  b.glide_to(0.2985);
  b.in.position.value = 0.2995;  // past soft_limit_high_m = 0.299
  ASSERT_EQ(b.step().state, AxisState::fault);
  ASSERT_EQ(b.sup.fault().reason, FaultReason::soft_limit);

  // The rod stopped outside: reset and enable are accepted, and the axis holds at the limit.
  Decision d = b.command(CommandKind::reset);
  ASSERT_TRUE(b.sup.last_command().accepted);
  ASSERT_EQ(d.state, AxisState::disabled);
  d = b.command(CommandKind::enable);
  ASSERT_EQ(d.state, AxisState::enabled);
  EXPECT_FALSE(b.sup.soft_limits_armed());
  b.run(20);
  d = b.last;
  EXPECT_EQ(d.state, AxisState::enabled);
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, b.params.soft_limit_high_m - kSoftLimitSetpointMarginM);  // the held position, clamped

  // Open loop stays closed while outside.
  b.command(CommandKind::set_mode, ControlMode::open_loop);
  d = b.setpoint(0.5);
  EXPECT_EQ(d.mode, ControlMode::open_loop);
  EXPECT_EQ(d.opening, 0.0);
  b.command(CommandKind::set_mode, ControlMode::position);

  // Inside again without a new setpoint: still recovering (the rod hovers at the limit).
  b.in.position.value = 0.2989;
  b.run(3);
  EXPECT_FALSE(b.sup.soft_limits_armed());
  b.in.position.value = 0.2991;
  d = b.step();
  EXPECT_EQ(d.state, AxisState::enabled);
  // A new setpoint, inward: armed once the rod is inside, and a later crossing trips again.
  b.setpoint(0.150);
  EXPECT_FALSE(b.sup.soft_limits_armed());
  b.in.position.value = 0.2985;
  b.setpoint(0.150);
  EXPECT_TRUE(b.sup.soft_limits_armed());
  b.in.position.value = 0.2995;
  d = b.step();
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::soft_limit);
}

TEST(AxisSupervisor, EnabledInsideTheSoftLimitsTheCheckIsArmedAtOnce) {
  Bench b;
  b.enable();
  EXPECT_TRUE(b.sup.soft_limits_armed());
  b.glide_to(0.2985);
  b.in.position.value = 0.2995;
  EXPECT_EQ(b.step().state, AxisState::fault);  // no setpoint was ever sent: still judged
}

TEST(AxisSupervisor, EnabledOnlyClassesDoNotTripWhileDisabled) {
  Bench b;
  b.step();
  b.glide_to(0.301);  // outside the soft limits while parked: no fault
  b.in.following_error_m = 0.5;
  b.in.command_saturated = true;
  b.run(10);
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
  EXPECT_NE(b.sup.active_faults() & fault_bit(FaultReason::soft_limit), 0u);
}

TEST(AxisSupervisor, PersistentClassesTripWhileDisabled) {
  Bench b;
  b.step();
  b.in.pressure_a.value = 27e5;
  const Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::over_pressure);
}

TEST(AxisSupervisor, SimultaneousFaultsLatchTheFirstByPriority) {
  Bench b;
  b.enable();
  b.in.pressure_a.value = 27e5;
  b.in.executive.driver_error = true;
  b.step();
  EXPECT_EQ(b.sup.fault().reason, FaultReason::driver_error);
  EXPECT_NE(b.sup.active_faults() & fault_bit(FaultReason::over_pressure), 0u);
}

TEST(AxisSupervisor, FollowingErrorNeedsAnUnbrokenStreak) {
  Bench b;
  b.enable();
  for (int round = 0; round < 3; ++round) {
    b.in.following_error_m = 0.02;
    b.run(4);  // one short of the limit
    b.in.following_error_m = 0.0;
    b.step();
  }
  EXPECT_EQ(b.sup.state(), AxisState::enabled);
}

TEST(AxisSupervisor, EstopGoesToEstopFromEnabledAndNeedsReleaseBeforeReset) {
  Bench b;
  b.enable();
  b.in.estop.value = true;
  Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::estop);
  EXPECT_FALSE(d.drive);
  EXPECT_TRUE(d.tripped);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::estop);
  EXPECT_EQ(describe(b.sup.fault()), "e-stop pressed");

  b.command(CommandKind::enable);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::estop_active);
  b.command(CommandKind::reset);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::estop_pressed);
  EXPECT_EQ(b.sup.state(), AxisState::estop);

  b.in.estop.value = false;
  d = b.step();
  EXPECT_EQ(d.state, AxisState::estop);  // released, still latched
  d = b.command(CommandKind::reset);
  EXPECT_EQ(d.state, AxisState::disabled);
}

// A latched fault keeps its first cause until a reset succeeds: an e-stop asserted or unreadable
// meanwhile (a recovered bus that has read nothing yet) refuses the reset, and replaces nothing.
TEST(AxisSupervisor, AnEstopInFaultKeepsTheFirstCauseAndRefusesTheReset) {
  for (const bool unreadable : {false, true}) {
    SCOPED_TRACE(unreadable ? "e-stop unreadable" : "e-stop pressed");
    Bench b;
    b.enable();
    b.in.executive.driver_error = true;
    b.step();
    b.in.executive.driver_error = false;
    ASSERT_EQ(b.sup.state(), AxisState::fault);
    const FaultRecord first = b.sup.fault();
    ASSERT_EQ(first.reason, FaultReason::driver_error);

    if (unreadable) {
      b.in.estop.status = SampleStatus::disconnected;
    } else {
      b.in.estop.value = true;
    }
    Decision d = b.step();
    EXPECT_EQ(d.state, AxisState::fault);
    EXPECT_FALSE(d.drive);
    EXPECT_FALSE(d.tripped);
    EXPECT_NE(b.sup.active_faults() & fault_bit(FaultReason::estop), 0u);
    d = b.command(CommandKind::reset);
    EXPECT_FALSE(b.sup.last_command().accepted);
    EXPECT_EQ(b.sup.last_command().refusal, Refusal::cause_present);
    EXPECT_EQ(b.sup.last_command().blocking, FaultReason::estop);
    EXPECT_EQ(d.state, AxisState::fault);
    EXPECT_EQ(b.sup.fault().reason, first.reason);
    EXPECT_EQ(b.sup.fault().t_ns, first.t_ns);
    EXPECT_EQ(b.sup.faults_tripped(), 1u);

    b.in.estop = {false, {}, SampleStatus::ok};
    b.step();
    d = b.command(CommandKind::reset);
    EXPECT_TRUE(b.sup.last_command().accepted);
    EXPECT_EQ(d.state, AxisState::disabled);
  }
}

TEST(AxisSupervisor, UnreadableEstopCountsAsPressed) {
  Bench b;
  b.step();
  b.in.estop.status = SampleStatus::disconnected;
  const Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::estop);
  EXPECT_EQ(describe(b.sup.fault()), "e-stop input disconnected");
}

TEST(AxisSupervisor, ResetFromEstopWaitsForOtherCausesToo) {
  Bench b;
  b.step();
  b.in.estop.value = true;
  b.step();
  b.in.estop.value = false;
  b.in.pressure_b.status = SampleStatus::stale;
  b.command(CommandKind::reset);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::cause_present);
  EXPECT_EQ(b.sup.last_command().blocking, FaultReason::sensor_not_ok);
  EXPECT_EQ(b.sup.state(), AxisState::estop);
}

TEST(AxisSupervisor, FollowsNewSetpointsClampedToTheSoftLimits) {
  Bench b;
  b.enable();
  Decision d = b.setpoint(0.200);
  EXPECT_FALSE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.200);
  d = b.setpoint(0.350);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, b.params.soft_limit_high_m - kSoftLimitSetpointMarginM);
  d = b.setpoint(-1.0);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, b.params.soft_limit_low_m + kSoftLimitSetpointMarginM);
  EXPECT_EQ(b.sup.setpoints_received(), 3u);
}

TEST(AxisSupervisor, HoldsThePositionAtEnableUntilANewSetpointArrives) {
  Bench b;
  b.step();
  b.setpoint(0.250);  // sent while disabled: not followed after enable
  b.glide_to(0.140);
  Decision d = b.command(CommandKind::enable);
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.140);
  d = b.setpoint(0.160);
  EXPECT_FALSE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.160);
}

TEST(AxisSupervisor, SetpointSilenceHoldsThePositionWithoutFaulting) {
  Bench b(test_params(/*encoder_jump_max_m=*/1.0));  // the rod may move in big steps here
  b.enable();
  b.setpoint(0.200);
  b.in.position.value = 0.170;  // on its way
  b.run(10);                    // exactly the timeout: still following
  EXPECT_FALSE(b.last.holding);
  EXPECT_DOUBLE_EQ(b.last.rod_setpoint_m, 0.200);
  Decision d = b.step();  // one period past it
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.170);
  b.in.position.value = 0.171;  // the hold point stays where the silence began
  d = b.step();
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.170);
  EXPECT_EQ(d.state, AxisState::enabled);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::none);
  d = b.setpoint(0.180);
  EXPECT_FALSE(d.holding);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.180);
}

TEST(AxisSupervisor, ModeChangeWhileEnabledReactivatesAndHoldsUntilANewSetpoint) {
  Bench b;
  b.enable();
  b.setpoint(0.200);
  Decision d = b.command(CommandKind::set_mode, ControlMode::open_loop);
  EXPECT_TRUE(d.activate);
  EXPECT_EQ(d.mode, ControlMode::open_loop);
  EXPECT_TRUE(d.holding);
  EXPECT_DOUBLE_EQ(d.opening, 0.0);  // 0.200 was a position, not an opening
  d = b.setpoint(0.3);
  EXPECT_DOUBLE_EQ(d.opening, 0.3);
  d = b.setpoint(4.0);
  EXPECT_DOUBLE_EQ(d.opening, 1.0);
  // Following error is not judged in open loop.
  b.in.following_error_m = 1.0;
  b.run(10);
  EXPECT_EQ(b.sup.state(), AxisState::enabled);
}

TEST(AxisSupervisor, ModeChangeWhileDisabledIsStoredWithoutActivation) {
  Bench b;
  b.step();
  const Decision d = b.command(CommandKind::set_mode, ControlMode::open_loop);
  EXPECT_FALSE(d.activate);
  EXPECT_EQ(b.sup.mode(), ControlMode::open_loop);
  EXPECT_TRUE(b.sup.last_command().accepted);
}

// A stall of 50 ms between two cycles of an ENABLED axis faults in the cycle after it, whatever
// the overrun streak, with the gap as the fault's value; the next on-time cycle lets a reset
// through. While DISABLED (valve safe) a late cycle is no fault.
TEST(AxisSupervisor, BlindTimeFaultsAnEnabledAxisWithTheGapAsItsValue) {
  Bench b;
  b.next_gap = 20 * kPeriod;
  b.step();
  EXPECT_EQ(b.sup.state(), AxisState::disabled);  // 2 ms: within the bound, and not enabled
  b.next_gap = 50'000'000;
  b.step();
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
  b.enable();
  b.setpoint(0.150);
  b.next_gap = 50 * kPeriod;  // exactly the bound: fine
  EXPECT_EQ(b.step().state, AxisState::enabled);
  b.in.executive.overrun_streak = 1;
  b.next_gap = 50'000'000;
  const Decision d = b.step();
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_FALSE(d.drive);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::blind_time);
  EXPECT_DOUBLE_EQ(b.sup.fault().value, 0.050);
  EXPECT_DOUBLE_EQ(b.sup.fault().limit, 0.005);
  EXPECT_EQ(describe(b.sup.fault()), "blind time: 50.0 ms without a cycle (limit 5.0 ms)");
  b.in.executive.overrun_streak = 0;
  b.command(CommandKind::reset);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
}

// Every bound input is judged by its timestamp, not only the encoder.
TEST(AxisSupervisor, AnInputWhoseTimestampStopsFaultsNamingIt) {
  for (const FaultSignal which : {FaultSignal::pressure_b, FaultSignal::spool, FaultSignal::estop}) {
    Bench b;
    b.in.has_spool = true;
    b.in.spool = ok_sample(0.0);
    b.enable();
    b.setpoint(0.150);
    b.frozen = which;
    int cycles = 0;
    while (b.sup.state() == AxisState::enabled && cycles < 100) {  // to FAULT or ESTOP
      b.step();
      ++cycles;
    }
    SCOPED_TRACE(std::string(to_string(which)));
    // A silent e-stop loop counts as pressed.
    EXPECT_EQ(b.sup.fault().reason,
              which == FaultSignal::estop ? FaultReason::estop : FaultReason::sensor_not_ok);
    EXPECT_EQ(b.sup.fault().signal, which);
    EXPECT_EQ(b.sup.fault().status, SampleStatus::stale);
    EXPECT_GT(b.sup.fault().value, b.sup.fault().limit);
    EXPECT_EQ(cycles, 6);  // the 6th update sees the same timestamp 6 periods on: over 5
  }
}

// A driver in error is not read, so its samples keep their timestamps: that is the driver error,
// not a stale input (nor, for the e-stop, a press). Once it reads again the clocks restart.
TEST(AxisSupervisor, InputsOfAFailedDriverAreNotJudgedByAge) {
  Bench b;
  b.enable();
  b.setpoint(0.150);
  b.in.executive.driver_error = true;
  b.frozen = FaultSignal::estop;
  b.fresh_pressure_a = false;
  b.run(50);  // ten times input_stale_ns
  EXPECT_EQ(b.sup.state(), AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::driver_error);
  EXPECT_EQ(b.sup.active_faults(), fault_bit(FaultReason::driver_error));
  // Recovered: fresh samples again, and a reset goes through.
  b.in.executive.driver_error = false;
  b.frozen = FaultSignal::none;
  b.fresh_pressure_a = true;
  b.command(CommandKind::reset);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
}

// A 0.2 m/s speed bound and the given jump margin, with staleness bounds far beyond the sample gaps
// of the slow-bus tests below, so that only the jump check is judged.
SupervisorParams slow_bus_params(double jump_margin_m) {
  SupervisorParams p = test_params(jump_margin_m);
  p.max_speed_m_s = 0.2;
  p.encoder_stale_cycles = 1000;
  p.input_stale_ns = 1'000'000'000;
  return p;
}

// A slow bus: samples 10 ms apart, the rod at 0.19 m/s under a 0.2 m/s bound, 1.9 mm between
// samples with a margin of 0.5 mm. A per-cycle limit would have faulted; judged by time it does
// not, and neither does a 50 ms gap in the samples at that speed. A real jump still faults, with
// the allowance max speed × Δt + margin as its limit.
TEST(AxisSupervisor, EncoderJumpIsJudgedAgainstTheTimeBetweenSamples) {
  const SupervisorParams p = slow_bus_params(0.0005);
  Bench b(p);
  b.enable();
  b.setpoint(0.150);
  const auto sample_after = [&](int periods, double dx) {
    b.fresh_encoder = false;
    for (int i = 1; i < periods; ++i) b.step();
    b.fresh_encoder = true;
    b.in.position.value += dx;
    return b.step();
  };
  for (int k = 0; k < 20; ++k) ASSERT_EQ(sample_after(100, 0.0019).state, AxisState::enabled) << k;
  ASSERT_EQ(sample_after(500, 0.0095).state, AxisState::enabled);  // the bus stalled 50 ms
  const Decision d = sample_after(100, 0.010);
  EXPECT_EQ(d.state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::encoder_jump);
  EXPECT_NEAR(b.sup.fault().value, 0.010, 1e-12);  // a difference of two positions near 0.2 m
  EXPECT_NEAR(b.sup.fault().limit, 0.2 * 0.010 + 0.0005, 1e-15);
}

// The figures of the fault seen over Modbus under load: two fresh samples 25.75 ms apart while
// the rod ramps at its 0.2 m/s bound differ by 5.15 mm. Per cycle against 5 mm that was a jump;
// against 0.2 m/s × 25.75 ms + 5 mm it is not. The same 5.15 mm between samples 100 µs apart is.
TEST(AxisSupervisor, TheModbusCaseOf515mmIn2575msIsNoJump) {
  const SupervisorParams p = slow_bus_params(0.005);
  Bench b(p);
  b.enable();
  b.setpoint(0.150);
  b.next_gap = 0;
  b.fresh_encoder = false;
  for (int i = 1; i < 257; ++i) b.step();  // 256 periods of 100 µs ...
  b.fresh_encoder = true;
  b.in.position.value += 0.00515;
  b.t += 50'000;  // ... + 50 µs, and this step's 100 µs: 25.75 ms after the last fresh sample
  ASSERT_EQ(b.step().state, AxisState::enabled);
  b.in.position.value += 0.00515;  // the next sample, 100 µs later: allowed 5.02 mm
  EXPECT_EQ(b.step().state, AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::encoder_jump);
  EXPECT_NEAR(b.sup.fault().limit, 0.2 * 100e-6 + 0.005, 1e-12);
}

// A non-finite loop output latches control_output at once; nothing of it lingers after a reset.
TEST(AxisSupervisor, NonFiniteOutputLatchesControlOutput) {
  Bench b;
  b.enable();
  b.setpoint(0.150);
  b.sup.output_not_finite(std::numeric_limits<double>::quiet_NaN(), b.t);
  EXPECT_EQ(b.sup.state(), AxisState::fault);
  EXPECT_EQ(b.sup.fault().reason, FaultReason::control_output);
  EXPECT_EQ(b.sup.fault().t_ns, b.t);
  EXPECT_FALSE(b.step().drive);
  b.command(CommandKind::reset);
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_EQ(b.sup.state(), AxisState::disabled);
}

TEST(AxisSupervisor, FaultRecordsDescribeThemselvesInMillimetresAndBar) {
  FaultRecord r{FaultReason::over_pressure, FaultSignal::pressure_a, SampleStatus::ok, 27.1e5,
                26e5, 0};
  EXPECT_EQ(describe(r), "pressure A 27.1 bar over limit 26.0 bar");
  r = {FaultReason::following_error, FaultSignal::position, SampleStatus::ok, 0.0121, 0.010, 0};
  EXPECT_EQ(describe(r), "following error 12.10 mm over limit 10.00 mm");
  r = {FaultReason::sensor_not_ok, FaultSignal::pressure_b, SampleStatus::disconnected, 0, 0, 0};
  EXPECT_EQ(describe(r), "pressure B sample disconnected");
  EXPECT_EQ(to_string(FaultReason::current_saturated), "current_saturated");
  EXPECT_EQ(summary(FaultReason::encoder_stale), "encoder stale");
  r = {FaultReason::sensor_not_ok, FaultSignal::pressure_a, SampleStatus::stale, 0.1204, 0.1, 0};
  EXPECT_EQ(describe(r), "pressure A stale: no new sample for 120.4 ms (limit 100.0 ms)");
  r = {FaultReason::encoder_jump, FaultSignal::position, SampleStatus::ok, 0.00515, 0.005, 0};
  EXPECT_EQ(describe(r), "encoder jumped 5.15 mm between two samples (limit 5.00 mm)");
  EXPECT_EQ(to_string(FaultReason::blind_time), "blind_time");
  EXPECT_EQ(summary(FaultReason::control_output), "control output not finite");
}

}  // namespace
}  // namespace hsa::daemon

namespace hsa::daemon {
namespace {

SupervisorParams move_params() {
  SupervisorParams p = test_params();
  p.max_speed_m_s = 0.1;
  return p;
}

TEST(AxisSupervisorMove, IsRefusedWithItsReasonUnlessEnabledInPositionModeWithinTheLimits) {
  Bench b(move_params());
  b.step();
  b.move_to(0.200);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::not_enabled);
  EXPECT_FALSE(b.sup.last_command().accepted);
  b.enable();
  b.move_to(0.300);  // over the soft limit of 0.299 m
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::target_outside_limits);
  b.move_to(0.200, 0.2);  // twice the axis's speed bound
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::speed_over_limit);
  b.move_to(std::nan(""));
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::target_outside_limits);
  b.command(CommandKind::set_mode, ControlMode::open_loop);
  b.move_to(0.200);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::not_position_mode);
  // None of them changed the state: the axis is still enabled, holding.
  EXPECT_EQ(b.sup.state(), AxisState::enabled);
}

TEST(AxisSupervisorMove, FollowsItsProfileWithinTheBoundsAndHoldsTheTargetWithoutSilence) {
  Bench b(move_params());
  b.enable();
  b.step();  // holding at 150 mm: no setpoint yet
  Decision d = b.move_to(0.160, 0.05, 0.5);  // 10 mm at 50 mm/s: 0.1 s up, 0.1 s cruise, 0.1 s down
  EXPECT_TRUE(b.sup.last_command().accepted);
  EXPECT_FALSE(d.holding);
  double previous = d.rod_setpoint_m;
  EXPECT_NEAR(previous, 0.150, 1e-9);
  double fastest = 0.0;
  for (int k = 0; k < 4000; ++k) {  // 0.4 s, ten times the setpoint timeout of the test
    d = b.step();
    ASSERT_TRUE(d.drive);
    ASSERT_FALSE(d.holding);
    ASSERT_GE(d.rod_setpoint_m, previous - 1e-12);  // one way only
    fastest = std::max(fastest, (d.rod_setpoint_m - previous) / (kPeriod * 1e-9));
    previous = d.rod_setpoint_m;
  }
  EXPECT_LE(fastest, 0.05 * (1 + 1e-6));
  EXPECT_GT(fastest, 0.05 * 0.99);  // it did cruise
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.160);
  EXPECT_EQ(d.velocity_ff_m_s, 0.0);
}

// The axis's acceleration bound refuses a faster move; within it, the Decision carries the
// profile's velocity, acceleration and jerk, each within its bound, and says when it has ended.
TEST(AxisSupervisorMove, CarriesTheProfilesDerivativesWithinTheAxisBoundsAndRefusesAFasterAcceleration) {
  SupervisorParams p = move_params();
  p.max_accel_m_s2 = 0.5;
  p.max_jerk_m_s3 = 10.0;
  Bench b(p);
  b.enable();
  b.move_to(0.200, 0.05, 0.6);
  EXPECT_EQ(b.sup.last_command().refusal, Refusal::accel_over_limit);
  Decision d = b.move_to(0.160);  // 0.1 m/s, 0.5 m/s², 10 m/s³: T_j 0.05 s, T_a 0.15 s, no cruise
  ASSERT_TRUE(b.sup.last_command().accepted);
  EXPECT_DOUBLE_EQ(b.sup.move().peak_accel_m_s2(), 0.5);
  double top_accel = 0.0, top_jerk = 0.0;
  int under_way = 0;
  const int cycles = static_cast<int>(b.sup.move().duration_s() / (kPeriod * 1e-9)) + 100;
  for (int k = 0; k < cycles; ++k) {
    d = b.step();
    top_accel = std::max(top_accel, std::abs(d.accel_ff_m_s2));
    top_jerk = std::max(top_jerk, std::abs(d.jerk_ff_m_s3));
    under_way += d.move_under_way ? 1 : 0;
  }
  EXPECT_DOUBLE_EQ(top_accel, 0.5);
  EXPECT_DOUBLE_EQ(top_jerk, 10.0);
  EXPECT_NEAR(under_way * kPeriod * 1e-9, b.sup.move().duration_s(), 2 * kPeriod * 1e-9);
  EXPECT_FALSE(d.move_under_way);  // over: it holds the target
  EXPECT_EQ(d.accel_ff_m_s2, 0.0);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.160);
}

TEST(AxisSupervisorMove, UnconfiguredBoundsComeFromTheSpeed) {
  const MoveBounds bounds = move_bounds(move_params());  // 0.1 m/s
  EXPECT_DOUBLE_EQ(bounds.accel_m_s2, 0.1 / safety_defaults::kDefaultRampS);
  EXPECT_DOUBLE_EQ(bounds.jerk_m_s3, bounds.accel_m_s2 / safety_defaults::kDefaultJerkRampS);
}

TEST(AxisSupervisorMove, AStreamedSetpointOrADisableEndsIt) {
  Bench b(move_params());
  b.enable();
  b.move_to(0.200);
  b.run(10);
  const double moved_to = b.last.rod_setpoint_m;
  Decision d = b.setpoint(0.120);
  // The stream takes over from the move's setpoint through the limiter (no jump: within one
  // cycle at the speed bound), and reaches 0.120.
  EXPECT_NEAR(d.rod_setpoint_m, moved_to, 0.1 * kPeriod * 1e-9 + 1e-12);
  for (int k = 0; k < 5000; ++k) d = b.setpoint(0.120);
  EXPECT_DOUBLE_EQ(d.rod_setpoint_m, 0.120);
  b.run(5);
  EXPECT_DOUBLE_EQ(b.last.rod_setpoint_m, 0.120);  // the move does not come back

  b.move_to(0.200);
  b.command(CommandKind::disable);
  b.command(CommandKind::enable);
  d = b.step();
  EXPECT_TRUE(d.holding);  // enabled again: holding where the rod is, not moving
}

}  // namespace
}  // namespace hsa::daemon

namespace hsa::daemon {
namespace {

// The arrays indexed by fault class or by input are sized by counts that follow from the tables
// (fault.hpp): every class and every input below its count has a name, and the value one past the
// count is none of them, so a class or an input added without its slot cannot exist.
TEST(FaultTable, EveryClassAndInputBelowItsCountHasANameAndNoneIsBeyond) {
  for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
    const auto reason = static_cast<FaultReason>(r);
    EXPECT_NE(to_string(reason), "?") << r;
    EXPECT_NE(summary(reason), "?") << r;
    EXPECT_FALSE(describe(FaultRecord{.reason = reason}).empty()) << r;
  }
  EXPECT_EQ(to_string(static_cast<FaultReason>(kFaultReasonCount)), "?");
  for (std::size_t s = 1; s <= kFaultSignalCount; ++s) EXPECT_NE(to_string(static_cast<FaultSignal>(s)), "?") << s;
  EXPECT_EQ(to_string(static_cast<FaultSignal>(kFaultSignalCount + 1)), "?");
}

}  // namespace
// An opening that carries a duration is the axis's to end: held past the setpoint timeout without
// another message, then opening 0 from the first cycle at or past its end, to the base tick.
TEST(AxisSupervisor, ATimedOpeningIsHeldForItsDurationThenClosedByTheAxis) {
  Bench b;
  b.enable();
  b.command(CommandKind::set_mode, ControlMode::open_loop);
  const int periods = 25;  // longer than the setpoint timeout (10 periods), which would close it
  ASSERT_GT(periods * kPeriod, b.params.setpoint_timeout_ns);
  b.op.command = {b.op.command.seq + 1, CommandKind::set_mode, ControlMode::open_loop, {}, 0};
  b.op.command.has_opening = true;
  b.op.command.opening = 0.4;
  b.op.command.opening_duration_s = periods * kPeriod * 1e-9;
  int open_cycles = 0;
  for (Decision d = b.step(); d.opening == 0.4 && open_cycles <= 2 * periods; d = b.step()) ++open_cycles;
  EXPECT_EQ(open_cycles, periods);
  EXPECT_EQ(b.last.opening, 0.0);
  EXPECT_EQ(b.last.state, AxisState::enabled);
  b.run(3 * periods);
  EXPECT_EQ(b.last.opening, 0.0);
  EXPECT_TRUE(b.last.holding);  // silent since: holding opening 0, as after any opening
}

// A new setpoint (hsactl's opening 0 on Ctrl-C, a streamed one) ends a timed opening at once, and
// it does not come back.
TEST(AxisSupervisor, ANewSetpointEndsATimedOpening) {
  Bench b;
  b.enable();
  b.command(CommandKind::set_mode, ControlMode::open_loop);
  b.op.command = {b.op.command.seq + 1, CommandKind::set_mode, ControlMode::open_loop, {}, 0};
  b.op.command.has_opening = true;
  b.op.command.opening = -0.3;
  b.op.command.opening_duration_s = 1.0;
  EXPECT_DOUBLE_EQ(b.step().opening, -0.3);
  b.run(5);
  EXPECT_DOUBLE_EQ(b.last.opening, -0.3);
  EXPECT_EQ(b.setpoint(0.0).opening, 0.0);
  b.run(50);  // past the setpoint timeout, well within the second
  EXPECT_EQ(b.last.opening, 0.0);
  EXPECT_TRUE(b.last.holding);
}

}  // namespace hsa::daemon
