// An operator reset of an axis whose driver failed, through hsad's own pieces joined as main.cpp
// joins them (DriverSet, AxisLoop, DaemonCycle, OperatorService) on the sim plugin with its
// driver_error event. The test thread plays both threads in turn: it runs RT cycles by calling
// DaemonCycle::cycle and the operator thread's work by calling OperatorService::poll, so every
// interleaving below is deterministic. Commands enter through request_reset, what poll() does with
// a RESET from LCM.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "tests/daemon/hsad_pieces.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;

// hsad-sim.toml with the rig in lockstep and a driver_error event at `error_at_s`, whose bus comes
// back `outage_s` later on the daemon's clock (never, without it); `axes` copies of its axis, all
// on the one rig (a driver shared by several axes).
DaemonConfig sim_config(double error_at_s, int axes, std::optional<double> outage_s = std::nullopt) {
  DaemonConfig config = load_config(HSA_SIM_CONFIG);
  toml::table& settings = config.drivers.at(0).settings;
  settings.insert_or_assign("timing", "lockstep");
  toml::table event{{"at_s", error_at_s}, {"driver_error", true}};
  if (outage_s) event.insert_or_assign("driver_error_s", *outage_s);
  settings.insert_or_assign("events", toml::array{event});
  const AxisConfig axis = config.axes.at(0);
  config.axes.clear();
  for (int i = 0; i < axes; ++i) {
    config.axes.push_back(axis);
    config.axes.back().name = "axis" + std::to_string(i);
  }
  return config;
}

// hsad's pieces, with an operator poll after every RT cycle (hsad polls every 100 cycles; more
// often only makes the interleavings denser).
using Hsad = test::HsadPieces;

TEST(OperatorReset, RecoversTheFailedDriverThenResets) {
  Hsad hsad(sim_config(0.05, 1, 0.002));  // the bus fails after 500 lockstep reads, for 20 cycles
  ASSERT_TRUE(hsad.run_until(0, AxisState::disabled, 100));
  ASSERT_TRUE(hsad.run_until(0, AxisState::fault, 1000));
  EXPECT_EQ(hsad.telemetry(0).fault.reason, FaultReason::driver_error);
  EXPECT_EQ(hsad.rig().state(), io::DriverState::error);
  hsad.run(50);  // the RT cycle keeps skipping the driver; the fault stays
  EXPECT_EQ(hsad.telemetry(0).state, AxisState::fault);

  hsad.operators().request_reset(0);
  EXPECT_EQ(hsad.rig().state(), io::DriverState::active);  // recovered on this (the operator) thread
  EXPECT_EQ(hsad.telemetry(0).state, AxisState::fault);    // the reset itself waits for a clean cycle
  ASSERT_TRUE(hsad.run_until(0, AxisState::disabled, 10));
  EXPECT_EQ(hsad.telemetry(0).fault.reason, FaultReason::none);
  EXPECT_EQ(hsad.telemetry(0).last_command.kind, CommandKind::reset);
  EXPECT_TRUE(hsad.telemetry(0).last_command.accepted);
  EXPECT_EQ(hsad.operators().reset_refusal(0), "");
  // The rig is read again through the signals bound at start-up: fresh encoder samples.
  hsad.run(20);
  EXPECT_EQ(hsad.telemetry(0).active_faults, 0u);
  EXPECT_EQ(hsad.telemetry(0).state, AxisState::disabled);
}

TEST(OperatorReset, ABusThatFailsAgainAtOnceKeepsTheFaultAndTheNextResetTriesAgain) {
  // The bus fails on the first read and never comes back: every recovery configures, then fails
  // its first read again. Nothing was ever read, so the e-stop input is not ok either; the axis
  // keeps its first cause, the driver error, with the e-stop condition present too.
  Hsad hsad(sim_config(0.0, 1));
  ASSERT_TRUE(hsad.run_until(0, AxisState::fault, 100));
  hsad.run(10);
  EXPECT_EQ(hsad.telemetry(0).state, AxisState::fault);
  EXPECT_EQ(hsad.telemetry(0).fault.reason, FaultReason::driver_error);
  EXPECT_NE(hsad.telemetry(0).active_faults & fault_bit(FaultReason::estop), 0u);
  const FaultRecord first = hsad.telemetry(0).fault;
  const StatusSample before = hsad.operators().status(0);
  ASSERT_EQ(std::string(before.fault_text), "driver error ('rig': read failed)");

  for (int attempt = 0; attempt < 2; ++attempt) {
    hsad.operators().request_reset(0);
    EXPECT_EQ(hsad.rig().state(), io::DriverState::active) << attempt;  // recovery itself works
    hsad.run(10);
    EXPECT_EQ(hsad.rig().state(), io::DriverState::error) << attempt;
    EXPECT_NE(hsad.telemetry(0).last_command.kind, CommandKind::reset);  // never reached the RT side
    // A refused reset changes nothing: the state, the latched fault and its text stay.
    EXPECT_EQ(hsad.telemetry(0).state, AxisState::fault) << attempt;
    EXPECT_EQ(hsad.telemetry(0).fault.reason, first.reason) << attempt;
    EXPECT_EQ(hsad.telemetry(0).fault.t_ns, first.t_ns) << attempt;
    const StatusSample after = hsad.operators().status(0);
    EXPECT_EQ(after.state, AxisState::fault);
    EXPECT_EQ(after.fault, FaultReason::driver_error);
    EXPECT_STREQ(after.fault_text, before.fault_text) << attempt;
    // The refusal is its sender's result, with the standing cause, worded once.
    const std::string why = "driver 'rig' failed again right after its recovery ('rig': read failed)";
    EXPECT_EQ(hsad.operators().reset_refusal(0), why);
    ASSERT_FALSE(hsad.operators().command_results(0).empty());
    const CommandResults::Result& result = hsad.operators().command_results(0).back();
    EXPECT_FALSE(result.accepted);
    EXPECT_EQ(result.reason, why);
    ASSERT_GT(after.num_results, 0);
    EXPECT_STREQ(after.results[after.num_results - 1].reason, why.c_str());
  }
}

TEST(OperatorReset, ADriverSharedByTwoAxesIsRecoveredOnceAndEachAxisNeedsItsOwnReset) {
  Hsad hsad(sim_config(0.05, 2, 0.002));
  ASSERT_TRUE(hsad.run_until(0, AxisState::fault, 1000));
  hsad.run(50);  // past the 20-cycle outage
  EXPECT_EQ(hsad.telemetry(0).fault.reason, FaultReason::driver_error);
  EXPECT_EQ(hsad.telemetry(1).state, AxisState::fault);
  EXPECT_EQ(hsad.telemetry(1).fault.reason, FaultReason::driver_error);

  hsad.operators().request_reset(0);
  ASSERT_TRUE(hsad.run_until(0, AxisState::disabled, 10));
  hsad.run(20);
  // Axis 1 still holds its latched fault, but its signals read the recovered rig like axis 0's.
  EXPECT_EQ(hsad.telemetry(1).state, AxisState::fault);
  EXPECT_EQ(hsad.telemetry(1).fault.reason, FaultReason::driver_error);
  EXPECT_EQ(hsad.telemetry(1).active_faults, 0u);
  EXPECT_EQ(hsad.telemetry(1).position_m, hsad.telemetry(0).position_m);

  hsad.operators().request_reset(1);  // the driver is running: nothing to recover, reset at once
  EXPECT_EQ(hsad.rig().state(), io::DriverState::active);
  ASSERT_TRUE(hsad.run_until(1, AxisState::disabled, 10));
  EXPECT_EQ(hsad.telemetry(0).state, AxisState::disabled);
  EXPECT_EQ(hsad.operators().reset_refusal(1), "");
}

}  // namespace
}  // namespace hsa::daemon
