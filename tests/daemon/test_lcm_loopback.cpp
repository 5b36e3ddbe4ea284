// The LCM bridge end to end over real LCM multicast, on loopback inside a private network
// namespace (ctest runs this binary under `unshare -n`, label netns; see lcm_bridge.cmake).
//
// A client LCM instance in this process plays the operator: it publishes setpoints and commands
// and listens to telemetry and status. The test thread plays the RT thread: it pops from and
// pushes into the bridge's rings. Every wait is bounded; nothing asserts timing beyond "arrives
// within seconds" and "not within a window much shorter than the configured period".
#include <gtest/gtest.h>
#include <net/if.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "daemon/lcm_bridge/lcm_bridge.hpp"
#include "daemon/lcm_bridge/lcm_url.hpp"
#include "msgs/auth/message_mac.hpp"
#include "msgs/auth/status_mac.hpp"
#include "hsa/command_t.hpp"
#include "hsa/setpoint_t.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::daemon {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// ttl=0 as well: even if the namespace guard below were bypassed, nothing leaves the host.
constexpr const char* kUrl = "udpm://239.255.76.67:7667?ttl=0";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// True when the only network interface is lo: we are in a private namespace, not on the host.
bool only_loopback_interface(std::string& seen) {
  struct if_nameindex* ifs = if_nameindex();
  if (ifs == nullptr) return false;
  bool only_lo = true;
  for (auto* i = ifs; i->if_index != 0; ++i) {
    seen += std::string(i->if_name) + " ";
    if (std::strcmp(i->if_name, "lo") != 0) only_lo = false;
  }
  if_freenameindex(ifs);
  return only_lo;
}

template <typename Pred>
bool wait_until(Pred pred, Clock::duration timeout, lcm::LCM* pump = nullptr) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (pred()) return true;
    if (pump != nullptr) {
      pump->handleTimeout(2);
    } else {
      std::this_thread::sleep_for(1ms);
    }
  }
  return pred();
}

// Keeps handling the client's messages for `duration` (to see whether more arrive).
void pump_for(lcm::LCM& lcm, Clock::duration duration) {
  const auto deadline = Clock::now() + duration;
  while (Clock::now() < deadline) lcm.handleTimeout(2);
}

hsa::setpoint_t setpoint(std::int64_t seq, double position, bool has_ff = false, double ff = 0.0) {
  hsa::setpoint_t s{};
  s.utime = seq * 100;
  s.seq = seq;
  s.position_m = position;
  s.has_velocity_ff = has_ff;
  s.velocity_ff_m_s = ff;
  return s;
}

hsa::command_t command(std::int64_t seq, std::int8_t kind) {
  hsa::command_t c{};
  c.seq = seq;
  c.command = kind;
  return c;
}

template <typename Msg>
struct Collector {
  std::vector<Msg> received;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* msg) { received.push_back(*msg); }
};

class LcmLoopback : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string seen;
    ASSERT_TRUE(only_loopback_interface(seen))
        << "refusing to send multicast: interfaces [" << seen
        << "] mean this is not a private network namespace. Run via `ctest -L netns`, which wraps "
           "the binary in `unshare -n`.";
    // Opened only now: even joining the multicast group must not happen on the host network.
    client_ptr_ = std::make_unique<lcm::LCM>(lcm_url_with_recv_buf(kUrl, kDefaultRecvBufSize));
    ASSERT_TRUE(client_ptr_->good()) << "client LCM did not open on " << kUrl;
  }

  // The one operator the bridges of these tests obey.
  static msgs::Key operator_key() {
    msgs::Key k;
    for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<unsigned char>(7 * i + 1);
    return k;
  }

  static LcmBridgeConfig config(std::vector<AxisEndpoint> axes) {
    LcmBridgeConfig c;
    c.axes = std::move(axes);
    c.lcm_url = kUrl;
    c.auth.keys = {{"op", operator_key()}};
    c.auth.system = kSystem;
    c.auth.instance = kInstance;
    return c;
  }

  // bob, a second operator: op's key with one bit changed.
  static msgs::Key second_operator_key() {
    msgs::Key k = operator_key();
    k[5] ^= 0x20;
    return k;
  }
  static LcmBridgeConfig config_with_bob(std::vector<AxisEndpoint> axes) {
    LcmBridgeConfig c = config(std::move(axes));
    c.auth.keys.push_back({"bob", second_operator_key()});
    return c;
  }

  // The daemon the tests' bridges are: what a client learns from their first verified status.
  static constexpr const char* kSystem = "test-rig";
  static constexpr std::int64_t kInstance = 0x1122'3344'5566'7788;

  // Publishes `msg` as an operator client does: signed by `op` for this daemon, with a new counter
  // and the time.
  template <typename Message>
  int publish(const std::string& channel, Message msg, const msgs::Key& key = operator_key(),
              const std::string& op = "op", std::int64_t instance = kInstance) {
    msg.system = kSystem;
    msg.instance = instance;
    msg.operator_id = op;
    msg.counter = ++counter_;
    msg.stamp_us = wall_clock_us();
    const std::vector<std::uint8_t> bytes = msgs::encode_signed(msg, key, channel);
    return client().publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
  }

  std::int64_t counter_ = 0;

  // Every status of axis x that the client hears goes into `got`.
  void collect_status(Collector<hsa::status_t>& got) {
    ASSERT_NE(client().subscribe(status_channel("x"), &Collector<hsa::status_t>::on, &got), nullptr);
  }

  // The client needs a deliberate receive buffer too: with the kernel default it loses part of a
  // 10 kHz telemetry burst, which is the very problem the bridge's own setting addresses.
  std::unique_ptr<lcm::LCM> client_ptr_;
  lcm::LCM& client() { return *client_ptr_; }
};

TEST_F(LcmLoopback, OnlyValidSetpointsAndCommandsReachTheRings) {
  LcmBridge bridge(config({{"x", {0.0, 0.3, 0.5}}, {"y", {0.0, 0.5}}}));
  EXPECT_NE(bridge.lcm_url().find("recv_buf_size="), std::string::npos);
  bridge.start();
  AxisPort& x = bridge.axis(0);
  AxisPort& y = *bridge.find_axis("y");

  const std::string sp = setpoint_channel("x");
  auto send = [&](const hsa::setpoint_t& s) { ASSERT_EQ(publish(sp, s), 0); };
  send(setpoint(1, 0.10));
  send(setpoint(2, kNaN));            // non_finite
  send(setpoint(3, 0.20, true, 0.1));
  send(setpoint(4, 0.40));            // out_of_range for x (in range for y)
  send(setpoint(5, 0.15, true, kInf));  // non_finite feed-forward
  // seq 6 never sent: one message lost on the way.
  send(setpoint(7, 0.25));
  const std::uint8_t junk[5] = {0xde, 0xad, 0xbe, 0xef, 0x00};
  ASSERT_EQ(client().publish(sp, junk, sizeof junk), 0);  // decode
  const hsa::command_t wrong_type = command(1, hsa::command_t::ENABLE);
  ASSERT_EQ(publish(sp, wrong_type), 0);        // decode: a command on the setpoint channel

  const hsa::setpoint_t for_y = setpoint(1, 0.40);
  ASSERT_EQ(publish(setpoint_channel("y"), for_y), 0);

  const std::string cmd = command_channel("x");
  const hsa::command_t enable = command(1, hsa::command_t::ENABLE);
  const hsa::command_t unknown = command(2, 42);
  hsa::command_t bad_gains = command(3, hsa::command_t::GAINS);
  bad_gains.kp = -1.0;
  bad_gains.ki = 1.0;
  ASSERT_EQ(publish(cmd, enable), 0);
  ASSERT_EQ(publish(cmd, unknown), 0);
  ASSERT_EQ(publish(cmd, bad_gains), 0);

  // 8 setpoint messages and 3 commands on x, 1 setpoint on y: wait until all are accounted for.
  const bool all_seen = wait_until(
      [&] {
        const AxisCounters c = x.counters();
        return c.setpoints_accepted + c.commands_accepted + c.rejected_total() >= 11 &&
               y.counters().setpoints_accepted >= 1;
      },
      5s);
  bridge.stop();
  ASSERT_TRUE(all_seen) << "messages did not reach the bridge within 5 s";

  const AxisCounters c = x.counters();
  EXPECT_EQ(c.setpoints_accepted, 3u);
  EXPECT_EQ(c.commands_accepted, 1u);
  EXPECT_EQ(c.rejected_for(RejectReason::non_finite), 2u);
  EXPECT_EQ(c.rejected_for(RejectReason::out_of_range), 2u);  // position 0.4, kp -1
  EXPECT_EQ(c.rejected_for(RejectReason::decode), 2u);
  EXPECT_EQ(c.rejected_for(RejectReason::unknown), 1u);
  EXPECT_EQ(c.lcm_seq_gaps, 1u);
  EXPECT_EQ(c.setpoint_ring_drops, 0u);

  // The ring holds exactly the valid setpoints, in order.
  SetpointInput m;
  std::vector<std::int64_t> seqs;
  std::vector<double> positions;
  while (x.pop_setpoint(m)) {
    seqs.push_back(static_cast<std::int64_t>(m.seq));
    positions.push_back(m.target);
    EXPECT_TRUE(std::isfinite(m.target));
  }
  EXPECT_EQ(seqs, (std::vector<std::int64_t>{1, 3, 7}));
  EXPECT_EQ(positions, (std::vector<double>{0.10, 0.20, 0.25}));

  OperatorCommand cm;
  ASSERT_TRUE(x.pop_command(cm));
  EXPECT_EQ(cm.command.kind, CommandKind::enable);
  EXPECT_FALSE(x.pop_command(cm));

  ASSERT_TRUE(y.pop_setpoint(m));
  EXPECT_DOUBLE_EQ(m.target, 0.40);
  EXPECT_FALSE(y.pop_setpoint(m));
  EXPECT_EQ(y.counters().rejected_total(), 0u);
}

// The bridge publishes every sample the RT thread pushes, in order and unchanged: the RT thread
// chose them (daemon/axis/tick_decimator.hpp), so a second choice here could only lose some.
TEST_F(LcmLoopback, TelemetryPublishesEverySamplePushedInOrder) {
  auto cfg = config({{"x", {0.0, 0.3}}});
  cfg.rings.telemetry = 4096;
  LcmBridge bridge(cfg);

  Collector<hsa::telemetry_t> got;
  lcm::Subscription* sub = client().subscribe(telemetry_channel("x"), &Collector<hsa::telemetry_t>::on, &got);
  ASSERT_NE(sub, nullptr);
  sub->setQueueCapacity(10'000);
  bridge.start();

  // 0.2 s of a 10 kHz RT loop publishing at 250 Hz: every 40th tick, pushed at once.
  constexpr std::uint64_t kTicks = 2000;
  constexpr std::uint64_t kStep = 40;
  AxisPort& x = bridge.axis(0);
  for (std::uint64_t tick = 0; tick < kTicks; tick += kStep) {
    TelemetrySample s;
    s.tick = tick;
    s.utime = static_cast<std::int64_t>(tick) * 100;
    s.position_m = static_cast<double>(tick) * 1e-4;
    s.state = AxisState::enabled;
    ASSERT_TRUE(x.push_telemetry(s));
  }
  const std::size_t expected = kTicks / kStep;
  const bool arrived = wait_until([&] { return got.received.size() >= expected; }, 5s, &client());
  pump_for(client(), 200ms);  // anything beyond the expected count would show up here
  bridge.stop();
  ASSERT_TRUE(arrived) << "got " << got.received.size() << " of " << expected << " telemetry messages";

  EXPECT_EQ(got.received.size(), expected);
  EXPECT_EQ(x.counters().telemetry_published, expected);
  EXPECT_EQ(x.counters().telemetry_ring_drops, 0u);
  for (std::size_t i = 0; i < got.received.size(); ++i) {
    const hsa::telemetry_t& t = got.received[i];
    ASSERT_EQ(t.seq, static_cast<std::int64_t>(i * kStep)) << "message " << i;
    EXPECT_DOUBLE_EQ(t.position_m, static_cast<double>(t.seq) * 1e-4);
    EXPECT_EQ(t.utime, t.seq * 100);
    EXPECT_EQ(t.state, int{hsa::status_t::STATE_ENABLED});
  }
}

TEST_F(LcmLoopback, StatusGoesOutAtOnceOnChangeOnly) {
  auto cfg = config({{"x", {0.0, 0.3}}});
  cfg.status_rate_hz = 0.2;  // periodic every 5 s: anything sooner is a change
  LcmBridge bridge(cfg);
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();
  AxisPort& x = bridge.axis(0);

  // The first status goes out at start.
  ASSERT_TRUE(wait_until([&] { return got.received.size() >= 1; }, 3s, &client()));
  EXPECT_EQ(got.received.front().state, int{hsa::status_t::STATE_INIT});

  StatusSample s;
  s.state = AxisState::enabled;
  s.sched_fifo = true;
  s.rt_priority = 80;
  ASSERT_TRUE(x.push_status(s));
  ASSERT_TRUE(wait_until([&] { return got.received.size() >= 2; }, 2s, &client()));
  EXPECT_EQ(got.received[1].state, int{hsa::status_t::STATE_ENABLED});
  EXPECT_TRUE(got.received[1].sched_fifo);
  EXPECT_EQ(got.received[1].rt_priority, 80);

  // Same state, new counters: not a change, so nothing before the next period.
  s.rt_overruns = 3;
  ASSERT_TRUE(x.push_status(s));
  pump_for(client(), 300ms);
  EXPECT_EQ(got.received.size(), 2u);

  s.state = AxisState::fault;
  s.fault = FaultReason::over_pressure;
  std::strcpy(s.fault_text, "pressure A 231 bar over limit 210 bar");
  ASSERT_TRUE(x.push_status(s));
  ASSERT_TRUE(wait_until([&] { return got.received.size() >= 3; }, 2s, &client()));
  bridge.stop();
  const hsa::status_t& fault = got.received[2];
  EXPECT_EQ(fault.state, int{hsa::status_t::STATE_FAULT});
  ASSERT_EQ(fault.num_faults, 1);
  EXPECT_EQ(fault.fault_code.at(0), int{hsa::status_t::FAULT_PRESSURE});
  EXPECT_EQ(fault.fault_reason.at(0), "pressure A 231 bar over limit 210 bar");
  EXPECT_EQ(fault.rt_overruns, 3);
}

TEST_F(LcmLoopback, PeriodicStatusReportsRejects) {
  auto cfg = config({{"x", {0.0, 0.3}}});
  cfg.status_rate_hz = 10.0;
  LcmBridge bridge(cfg);
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();

  const hsa::setpoint_t nan = setpoint(1, kNaN);
  const hsa::setpoint_t far = setpoint(2, 1.5);
  ASSERT_EQ(publish(setpoint_channel("x"), nan), 0);
  ASSERT_EQ(publish(setpoint_channel("x"), far), 0);
  // No change of state ever happens here: only the 10 Hz status can carry the counters.
  const bool reported = wait_until(
      [&] {
        // The first status goes out at start; a later one can only be periodic.
        return got.received.size() >= 2 && got.received.back().rejected_non_finite == 1 &&
               got.received.back().rejected_out_of_range == 1;
      },
      5s, &client());
  bridge.stop();
  ASSERT_TRUE(reported) << "status never showed the rejects (" << got.received.size() << " status messages)";
  EXPECT_GE(got.received.size(), 2u);  // the one at start, then periodic ones
  EXPECT_EQ(got.received.back().setpoints_accepted, 0);
  SetpointInput m;
  EXPECT_FALSE(bridge.axis(0).pop_setpoint(m));
}

TEST_F(LcmLoopback, OnlyTheKeyHoldersFreshMessagesAreHeard) {
  LcmBridge bridge(config({{"x", {0.0, 0.3}}}));
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();
  AxisPort& x = bridge.axis(0);
  const std::string cmd = command_channel("x");

  ASSERT_EQ(publish(cmd, command(1, hsa::command_t::ENABLE)), 0);  // accepted
  const hsa::command_t unsigned_disable = command(2, hsa::command_t::DISABLE);
  ASSERT_EQ(client().publish(cmd, &unsigned_disable), 0);  // unknown operator ("")
  msgs::Key other = operator_key();
  other[0] ^= 1;
  ASSERT_EQ(publish(cmd, command(3, hsa::command_t::DISABLE), other), 0);  // bad MAC
  ASSERT_EQ(publish(cmd, command(4, hsa::command_t::DISABLE), operator_key(), "eve"), 0);  // unknown operator
  // One signed message sent twice: the second is a replay.
  hsa::command_t reset = command(5, hsa::command_t::RESET);
  reset.system = kSystem;
  reset.instance = kInstance;
  reset.operator_id = "op";
  reset.counter = ++counter_;
  reset.stamp_us = wall_clock_us();
  const std::vector<std::uint8_t> bytes = msgs::encode_signed(reset, operator_key(), cmd);
  for (int i = 0; i < 2; ++i) ASSERT_EQ(client().publish(cmd, bytes.data(), static_cast<unsigned int>(bytes.size())), 0);
  // Stamped 10 s ago.
  hsa::command_t old = command(6, hsa::command_t::DISABLE);
  old.system = kSystem;
  old.instance = kInstance;
  old.operator_id = "op";
  old.counter = ++counter_;
  old.stamp_us = wall_clock_us() - 10'000'000;
  const std::vector<std::uint8_t> old_bytes = msgs::encode_signed(old, operator_key(), cmd);
  ASSERT_EQ(client().publish(cmd, old_bytes.data(), static_cast<unsigned int>(old_bytes.size())), 0);

  const bool all_seen = wait_until(
      [&] { return x.counters().commands_accepted + x.counters().rejected_total() >= 7; }, 5s, &client());
  // The stale stamp is the last refusal sent, and a status that went out between two refusals
  // carries only the first: wait for one that carries both.
  const bool reported = wait_until(
      [&] {
        return !got.received.empty() && got.received.back().rejected_replay == 1 &&
               got.received.back().rejected_stamp == 1;
      },
      5s, &client());
  bridge.stop();
  ASSERT_TRUE(all_seen && reported) << "commands did not reach the bridge within 5 s";
  const AxisCounters c = x.counters();
  EXPECT_EQ(c.commands_accepted, 2u);  // ENABLE and the first RESET
  EXPECT_EQ(c.rejected_for(RejectReason::unknown_operator), 2u);
  EXPECT_EQ(c.rejected_for(RejectReason::bad_mac), 1u);
  EXPECT_EQ(c.rejected_for(RejectReason::replay), 1u);
  EXPECT_EQ(c.rejected_for(RejectReason::stale_stamp), 1u);
  OperatorCommand m;
  ASSERT_TRUE(x.pop_command(m));
  EXPECT_EQ(m.command.kind, CommandKind::enable);
  ASSERT_TRUE(x.pop_command(m));
  EXPECT_EQ(m.command.kind, CommandKind::reset);
  EXPECT_FALSE(x.pop_command(m));
  // Refusals are counted, not answered; forged messages leave no trace in the seq gaps either.
  EXPECT_EQ(c.lcm_seq_gaps, 3u);  // seq 2, 3, 4 are not the operator's: gaps 1→5
  const hsa::status_t& s = got.received.back();
  EXPECT_TRUE(s.auth_required);
  EXPECT_EQ(s.warning, "");
  EXPECT_EQ(s.rejected_bad_mac, 1);
  EXPECT_EQ(s.rejected_unknown_operator, 2);
  EXPECT_EQ(s.rejected_stamp, 1);
}

TEST_F(LcmLoopback, TheLeaseHolderAloneCommandsAndEveryTakenCommandIsAcknowledged) {
  const msgs::Key bob_key = second_operator_key();
  LcmBridge bridge(config_with_bob({{"x", {0.0, 0.3}}}));
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();
  AxisPort& x = bridge.axis(0);
  const std::string cmd = command_channel("x");
  const auto ack_of = [](const hsa::status_t& s, const std::string& op) -> std::int64_t {
    for (int i = 0; i < s.num_acks; ++i) {
      if (s.ack_operator[i] == op) return s.ack_counter[i];
    }
    return -1;
  };
  const auto wait_for_status = [&](const std::function<bool(const hsa::status_t&)>& pred) {
    return wait_until([&] { return !got.received.empty() && pred(got.received.back()); }, 5s, &client());
  };

  // op takes the axis; the acknowledgement carries the ACQUIRE's counter.
  ASSERT_EQ(publish(cmd, command(1, hsa::command_t::ACQUIRE)), 0);
  const std::int64_t acquired = counter_;
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return s.lease_holder == "op" && ack_of(s, "op") == acquired; }));
  EXPECT_GT(got.received.back().lease_remaining_s, 29.0);

  // bob is refused for everything but DISABLE, setpoints included.
  ASSERT_EQ(publish(cmd, command(1, hsa::command_t::ENABLE), bob_key, "bob"), 0);
  ASSERT_EQ(publish(setpoint_channel("x"), setpoint(1, 0.1), bob_key, "bob"), 0);
  ASSERT_EQ(publish(cmd, command(2, hsa::command_t::ACQUIRE), bob_key, "bob"), 0);
  ASSERT_EQ(publish(cmd, command(3, hsa::command_t::DISABLE), bob_key, "bob"), 0);
  const std::int64_t bob_disable = counter_;
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return s.rejected_lease == 3 && ack_of(s, "bob") == bob_disable; }));
  OperatorCommand m;
  ASSERT_TRUE(x.pop_command(m));
  EXPECT_EQ(m.command.kind, CommandKind::disable);
  EXPECT_FALSE(x.pop_command(m));
  SetpointInput sp;
  EXPECT_FALSE(x.pop_setpoint(sp));

  // op's own commands go through; bob forces the lease over; then op is the one refused.
  ASSERT_EQ(publish(cmd, command(2, hsa::command_t::ENABLE)), 0);
  const std::int64_t enabled = counter_;
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return ack_of(s, "op") == enabled; }));
  ASSERT_TRUE(x.pop_command(m));
  EXPECT_EQ(m.command.kind, CommandKind::enable);
  hsa::command_t force = command(4, hsa::command_t::ACQUIRE);
  force.force = true;
  EXPECT_EQ(got.received.back().lease_takeovers, 0);
  const std::int64_t before_takeover_us = wall_clock_us();
  ASSERT_EQ(publish(cmd, force, bob_key, "bob"), 0);
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return s.lease_holder == "bob"; }));
  // The takeover is in the status, for every operator to see: who, from whom, when.
  const hsa::status_t& taken = got.received.back();
  EXPECT_EQ(taken.lease_takeovers, 1);
  EXPECT_EQ(taken.lease_taken_by, "bob");
  EXPECT_EQ(taken.lease_taken_from, "op");
  EXPECT_GE(taken.lease_taken_at_us, before_takeover_us);
  EXPECT_LE(taken.lease_taken_at_us, wall_clock_us());
  ASSERT_EQ(publish(cmd, command(3, hsa::command_t::ENABLE)), 0);
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return s.rejected_lease == 4; }));
  // bob gives it back; op commands again.
  ASSERT_EQ(publish(cmd, command(5, hsa::command_t::RELEASE), bob_key, "bob"), 0);
  ASSERT_EQ(publish(cmd, command(4, hsa::command_t::RESET)), 0);
  const std::int64_t reset = counter_;
  ASSERT_TRUE(wait_for_status([&](const auto& s) { return s.lease_holder.empty() && ack_of(s, "op") == reset; }));
  bridge.stop();
  EXPECT_EQ(x.counters().rejected_for(RejectReason::lease_held), 4u);
  // ACQUIRE, bob's DISABLE, ENABLE, bob's forced ACQUIRE, RELEASE, RESET.
  EXPECT_EQ(x.counters().commands_accepted, 6u);
}

TEST_F(LcmLoopback, StatusIsSignedForEachOperatorAndNamesThisDaemon) {
  const msgs::Key bob_key = second_operator_key();
  LcmBridge bridge(config_with_bob({{"x", {0.0, 0.3}}}));
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();
  AxisPort& x = bridge.axis(0);
  TelemetrySample sample;
  sample.utime = 4242;
  sample.position_m = 0.123;
  sample.setpoint_m = 0.125;
  ASSERT_TRUE(x.push_telemetry(sample));
  ASSERT_TRUE(wait_until([&] { return !got.received.empty() && got.received.back().sample_utime == 4242; }, 5s,
                         &client()));
  const std::int64_t now_us = wall_clock_us();
  const hsa::status_t s = got.received.back();
  EXPECT_EQ(s.system, kSystem);
  EXPECT_EQ(s.instance, kInstance);
  EXPECT_GT(s.stamp_us, now_us - 5'000'000);
  EXPECT_LE(s.stamp_us, now_us);
  EXPECT_DOUBLE_EQ(s.position_m, 0.123);
  EXPECT_DOUBLE_EQ(s.setpoint_m, 0.125);
  EXPECT_EQ(s.mac_operator, (std::vector<std::string>{"bob", "op"}));
  EXPECT_EQ(msgs::verify_status(s, {"op", operator_key()}, status_channel("x")), msgs::StatusMacCheck::verified);
  EXPECT_EQ(msgs::verify_status(s, {"bob", bob_key}, status_channel("x")), msgs::StatusMacCheck::verified);
  EXPECT_EQ(msgs::verify_status(s, {"op", bob_key}, status_channel("x")), msgs::StatusMacCheck::bad_mac);

  // The operator's own ENABLE, signed for another start of this daemon (or another rig): refused
  // and counted where the operator sees it. Signed for this one: taken.
  ASSERT_EQ(publish(command_channel("x"), command(1, hsa::command_t::ENABLE), operator_key(), "op", kInstance + 1), 0);
  ASSERT_TRUE(wait_until([&] { return !got.received.empty() && got.received.back().rejected_wrong_daemon == 1; }, 5s,
                         &client()));
  OperatorCommand m;
  EXPECT_FALSE(x.pop_command(m));
  ASSERT_EQ(publish(command_channel("x"), command(2, hsa::command_t::ENABLE)), 0);
  ASSERT_TRUE(wait_until([&] { return x.counters().commands_accepted == 1; }, 5s, &client()));
  bridge.stop();
  EXPECT_EQ(x.counters().rejected_for(RejectReason::wrong_daemon), 1u);
  EXPECT_EQ(x.counters().rejected_for(RejectReason::bad_mac), 0u);
  ASSERT_TRUE(x.pop_command(m));
  EXPECT_EQ(m.command.kind, CommandKind::enable);
}

TEST_F(LcmLoopback, WithoutAuthenticationAnyoneIsHeardAndEveryStatusSaysSo) {
  auto cfg = config({{"x", {0.0, 0.3}}});
  cfg.auth.required = false;
  cfg.auth.keys.clear();
  LcmBridge bridge(cfg);
  Collector<hsa::status_t> got;
  collect_status(got);
  bridge.start();
  const hsa::command_t enable = command(1, hsa::command_t::ENABLE);
  ASSERT_EQ(client().publish(command_channel("x"), &enable), 0);
  const bool seen = wait_until(
      [&] { return got.received.size() >= 2 && bridge.axis(0).counters().commands_accepted == 1; }, 5s, &client());
  bridge.stop();
  ASSERT_TRUE(seen);
  for (const hsa::status_t& s : got.received) {
    EXPECT_FALSE(s.auth_required);
    EXPECT_NE(s.warning.find("require_auth = false"), std::string::npos) << s.warning;
    EXPECT_EQ(s.num_macs, 0);  // no key, nothing to sign with: a client cannot verify it
  }
}

TEST_F(LcmLoopback, EveryMessageOfABurstIsAccountedFor) {
  // A burst faster than 10 kHz with nobody popping the ring: whatever LCM or the ring loses must
  // show up as a seq gap or a ring drop.
  auto cfg = config({{"x", {0.0, 0.3}}});
  cfg.rings.setpoints = 256;
  LcmBridge bridge(cfg);
  bridge.start();
  AxisPort& x = bridge.axis(0);

  constexpr std::int64_t kBurst = 3000;
  for (std::int64_t seq = 1; seq <= kBurst; ++seq) {
    const hsa::setpoint_t s = setpoint(seq, 0.1);
    ASSERT_EQ(publish(setpoint_channel("x"), s), 0);
  }
  // A last message after the burst has drained shows any loss at the end of the burst as a gap.
  std::this_thread::sleep_for(100ms);
  const hsa::setpoint_t last = setpoint(kBurst + 1, 0.2);
  ASSERT_EQ(publish(setpoint_channel("x"), last), 0);

  auto accounted = [&] {
    const AxisCounters c = x.counters();
    return c.setpoints_accepted + c.setpoint_ring_drops + c.lcm_seq_gaps;
  };
  const bool done = wait_until([&] { return accounted() >= static_cast<std::uint64_t>(kBurst + 1); }, 10s);
  bridge.stop();
  const AxisCounters c = x.counters();
  ASSERT_TRUE(done) << "accepted " << c.setpoints_accepted << ", ring drops " << c.setpoint_ring_drops
                    << ", seq gaps " << c.lcm_seq_gaps;
  EXPECT_EQ(accounted(), static_cast<std::uint64_t>(kBurst + 1));
  EXPECT_EQ(c.setpoints_accepted, 256u);  // the ring filled and nobody popped
  EXPECT_GT(c.setpoint_ring_drops, 0u);
  RecordProperty("lcm_seq_gaps", static_cast<int>(c.lcm_seq_gaps));
}

TEST_F(LcmLoopback, RestartsAfterStop) {
  LcmBridge bridge(config({{"x", {0.0, 0.3}}}));
  bridge.start();
  bridge.stop();
  bridge.stop();  // idempotent
  bridge.start();
  const hsa::setpoint_t s = setpoint(1, 0.05);
  ASSERT_EQ(publish(setpoint_channel("x"), s), 0);
  SetpointInput m;
  const bool got = wait_until([&] { return bridge.axis(0).pop_setpoint(m); }, 5s);
  bridge.stop();
  ASSERT_TRUE(got);
  EXPECT_DOUBLE_EQ(m.target, 0.05);
}

}  // namespace
}  // namespace hsa::daemon
