// A command's way through hsad's own pieces, joined as main.cpp joins them (DriverSet, AxisLoop,
// DaemonCycle, OperatorService) on the sim plugin in lockstep. The test thread plays the RT
// thread (DaemonCycle::cycle) and the operator thread (OperatorService::poll, every 100 cycles as
// hsad's 10 ms poll), so every interleaving is deterministic.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "daemon/axis/axis_signals.hpp"
#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"
#include "daemon/hsad/daemon_cycle.hpp"
#include "daemon/hsad/driver_set.hpp"
#include "daemon/hsad/operator_service.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t period_ns = 100'000;
constexpr int kCyclesPerPoll = 100;

DaemonConfig sim_config() {
  DaemonConfig config = load_config(HSA_SIM_CONFIG);
  config.drivers.at(0).settings.insert_or_assign("timing", "lockstep");
  return config;
}

class Hsad {
 public:
  Hsad() : config_(sim_config()), drivers_(config_) {
    const std::vector<io::DriverHandle*> handles = drivers_.handles();
    for (const AxisConfig& a : config_.axes) {
      const AxisParams params = axis_params(a, config_.realtime);
      AxisLimits limits;
      limits.min_position_m = a.limits.min_m;
      limits.max_position_m = a.limits.max_m;
      ports_.push_back(std::make_unique<AxisPort>(a.name, limits, RingCapacities{}));
      axes_.push_back(std::make_unique<AxisRuntime>(
          std::make_unique<AxisLoop>(params, bind_axis_signals(a.name, params.bindings, handles)),
          *ports_.back(), drivers_.mask_of(drivers_of(a))));
    }
    drivers_.activate_all();
    cycle_ = std::make_unique<DaemonCycle>(drivers_, axes_, watchdog_);
    executive_ = std::make_unique<RtExecutive>(RtConfig{}, *cycle_);
    operators_ = std::make_unique<OperatorService>(axes_, drivers_, *executive_, RtConfig{}, RealtimeGrant{});
  }

  // n RT cycles; the operator thread polls after every kCyclesPerPoll-th.
  void run(int n) {
    for (int i = 0; i < n; ++i) {
      ++tick_;
      const std::int64_t t = cycle_->epoch_ns() + static_cast<std::int64_t>(tick_) * period_ns;
      cycle_->cycle(CycleTiming{t, t, period_ns, tick_, 0, 0});
      if (tick_ % kCyclesPerPoll == 0) poll();
    }
  }
  void poll() {
    operators_->poll();
    for (const CommandResults::Result& r : operators_->command_results(0)) answered_.insert(r.counter);
  }
  bool run_until(AxisState state, int n) {
    for (int i = 0; i < n && telemetry().state != state; ++i) run(1);
    return telemetry().state == state;
  }
  // What the operator thread passes on to the RT thread.
  void forward(const AxisCommand& command) { ASSERT_TRUE(ports_[0]->push_axis_command(command)); }

  [[nodiscard]] const AxisTelemetry& telemetry() const { return axes_[0]->loop->telemetry(); }
  OperatorService& operators() { return *operators_; }
  // The counters of the commands whose answer the operator thread has given, over every poll.
  [[nodiscard]] const std::set<std::int64_t>& answered() const { return answered_; }

 private:
  DaemonConfig config_;
  DriverSet drivers_;
  std::vector<std::unique_ptr<AxisPort>> ports_;
  std::vector<std::unique_ptr<AxisRuntime>> axes_;
  SystemdWatchdog watchdog_;
  std::unique_ptr<DaemonCycle> cycle_;
  std::unique_ptr<RtExecutive> executive_;
  std::unique_ptr<OperatorService> operators_;
  std::uint64_t tick_ = 0;
  std::set<std::int64_t> answered_;
};

// One MODE message that switches an ENABLED axis to open loop and carries an opening opens the
// valve to it in the cycle that takes the command, as a second MODE would: no re-send needed.
TEST(CommandPath, AModeCommandToOpenLoopAppliesTheOpeningItCarries) {
  Hsad hsad;
  ASSERT_TRUE(hsad.run_until(AxisState::disabled, 1000));
  AxisCommand enable;
  enable.kind = CommandKind::enable;
  hsad.forward(enable);
  ASSERT_TRUE(hsad.run_until(AxisState::enabled, 10));
  AxisCommand open;
  open.kind = CommandKind::set_mode;
  open.mode = ControlMode::open_loop;
  open.has_opening = true;
  open.opening = 0.3;
  hsad.forward(open);
  hsad.run(1);
  EXPECT_EQ(hsad.telemetry().mode, ControlMode::open_loop);
  EXPECT_FALSE(hsad.telemetry().holding);
  EXPECT_DOUBLE_EQ(hsad.telemetry().opening, 0.3);
  hsad.run(50);  // and it keeps it (well inside the setpoint timeout)
  EXPECT_FALSE(hsad.telemetry().holding);
  EXPECT_DOUBLE_EQ(hsad.telemetry().opening, 0.3);
}

// Ten commands handed to the operator thread within one poll: each sender hears the axis's
// answer to its own command.
TEST(CommandPath, TenCommandsInOneBurstGetTenAnswers) {
  Hsad hsad;
  ASSERT_TRUE(hsad.run_until(AxisState::disabled, 1000));
  hsad.run(kCyclesPerPoll);
  CommandSender alice;
  std::strcpy(alice.operator_id, "alice");
  for (alice.counter = 1; alice.counter <= 10; ++alice.counter) hsad.operators().request_reset(0, alice);
  hsad.run(3 * kCyclesPerPoll);
  for (std::int64_t counter = 1; counter <= 10; ++counter) {
    EXPECT_TRUE(hsad.answered().contains(counter)) << "no answer to command " << counter;
  }
  // And one status carries all ten, in the order they were sent.
  const auto& results = hsad.operators().command_results(0);
  ASSERT_EQ(results.size(), 10u);
  for (std::size_t i = 0; i < results.size(); ++i) {
    EXPECT_EQ(results[i].operator_id, "alice");
    EXPECT_EQ(results[i].counter, static_cast<std::int64_t>(i + 1));
    EXPECT_TRUE(results[i].accepted) << results[i].reason;
  }
}

}  // namespace
}  // namespace hsa::daemon
