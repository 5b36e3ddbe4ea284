// A command's way through hsad's own pieces (tests/daemon/hsad_pieces.hpp) on the sim plugin in
// lockstep, the operator thread polling every 100 cycles as hsad's does every 10 ms.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "tests/daemon/hsad_pieces.hpp"

namespace hsa::daemon {
namespace {

constexpr int kCyclesPerPoll = 100;

DaemonConfig sim_config() {
  DaemonConfig config = load_config(HSA_SIM_CONFIG);
  config.drivers.at(0).settings.insert_or_assign("timing", "lockstep");
  return config;
}

// hsad's pieces, polled as hsad polls; it remembers every answer the operator thread has given.
class Hsad : public test::HsadPieces {
 public:
  Hsad() : HsadPieces(sim_config(), kCyclesPerPoll) {}

  void poll() override {
    HsadPieces::poll();
    for (const CommandResults::Result& r : operators().command_results(0)) answered_.insert(r.counter);
  }
  bool run_until(AxisState state, int n) { return HsadPieces::run_until(0, state, n); }
  [[nodiscard]] const AxisTelemetry& telemetry() const { return HsadPieces::telemetry(0); }
  // What the operator thread passes on to the RT thread.
  void forward(const AxisCommand& command) { ASSERT_TRUE(port(0).push_axis_command(command)); }
  // The counters of the commands whose answer the operator thread has given, over every poll.
  [[nodiscard]] const std::set<std::int64_t>& answered() const { return answered_; }

 private:
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
