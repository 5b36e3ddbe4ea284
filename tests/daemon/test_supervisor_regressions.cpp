// Sequences the supervisor's properties (test_axis_supervisor_properties.cpp) found breaking a
// rule, shrunk to their minimum, each kept as an ordinary test of that rule.
#include <gtest/gtest.h>

#include <limits>

#include "daemon/supervisor/axis_supervisor.hpp"

namespace hsa::daemon {
namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr std::int64_t kPeriod = 100'000;  // 100 µs

// A healthy axis with an e-stop, every input fresh each cycle.
struct Axis {
  Axis() {
    in.position = {0.150, {}, SampleStatus::ok};
    in.pressure_a = {12e5, {}, SampleStatus::ok};
    in.pressure_b = {9e5, {}, SampleStatus::ok};
    in.estop = {false, {}, SampleStatus::ok};
    in.has_estop = true;
  }
  void step() {
    t += kPeriod;
    in.t_ns = t;
    in.cycle_gap_ns = kPeriod;
    for (auto* s : {&in.position, &in.pressure_a, &in.pressure_b}) s->timestamp = nanoseconds(t);
    in.estop.timestamp = nanoseconds(t);
    sup.update(in, op);
  }
  void command(CommandKind kind) {
    op.command.seq += 1;
    op.command.kind = kind;
    step();
  }

  AxisSupervisor sup{SupervisorParams{}};
  SupervisorInputs in;
  AxisInputsFromOperator op;
  std::int64_t t = 0;
};

// Shrunk: [pressure(A, NaN), estop(pressed)]. The sensor fault was latched, and the e-stop that
// followed replaced its record, though only a successful reset may change it.
TEST(SupervisorRegression, AnEstopPressedInFaultKeepsTheLatchedCause) {
  Axis a;
  a.in.pressure_a.value = std::numeric_limits<double>::quiet_NaN();
  a.step();
  ASSERT_EQ(a.sup.state(), AxisState::fault);
  const FaultRecord latched = a.sup.fault();
  ASSERT_EQ(latched.reason, FaultReason::sensor_not_ok);
  ASSERT_EQ(latched.signal, FaultSignal::pressure_a);

  a.in.estop.value = true;
  a.step();
  EXPECT_EQ(a.sup.state(), AxisState::fault);  // the e-stop goes to ESTOP from any state but FAULT
  EXPECT_EQ(a.sup.fault().reason, FaultReason::sensor_not_ok);
  EXPECT_EQ(a.sup.fault().signal, FaultSignal::pressure_a);
  EXPECT_EQ(a.sup.fault().t_ns, latched.t_ns);
}

// The same rule as hsad meets it: a reset of a driver error recovers the driver first, and the
// recovered driver's e-stop reads disconnected until its first poll. The reset is refused, and the
// cause the operator sees must still be the driver error, not "e-stop input disconnected".
TEST(SupervisorRegression, ARefusedResetWhileTheRecoveredEstopReadsDisconnectedKeepsTheDriverError) {
  Axis a;
  a.step();
  a.in.executive.driver_error = true;
  a.step();
  ASSERT_EQ(a.sup.fault().reason, FaultReason::driver_error);

  a.in.executive.driver_error = false;
  a.in.estop.status = SampleStatus::disconnected;
  a.command(CommandKind::reset);
  EXPECT_FALSE(a.sup.last_command().accepted);
  EXPECT_EQ(a.sup.last_command().refusal, Refusal::cause_present);
  EXPECT_EQ(a.sup.last_command().blocking, FaultReason::estop);
  EXPECT_EQ(a.sup.state(), AxisState::fault);
  EXPECT_EQ(a.sup.fault().reason, FaultReason::driver_error);

  // Its first poll: the e-stop reads released, and the next reset clears the driver error.
  a.in.estop.status = SampleStatus::ok;
  a.command(CommandKind::reset);
  EXPECT_TRUE(a.sup.last_command().accepted);
  EXPECT_EQ(a.sup.state(), AxisState::disabled);
  EXPECT_EQ(a.sup.fault().reason, FaultReason::none);
}

}  // namespace
}  // namespace hsa::daemon
