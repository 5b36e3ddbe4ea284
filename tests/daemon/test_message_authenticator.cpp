// Authentication of incoming messages (daemon/lcm_bridge/message_authenticator.hpp): only an
// operator hsad holds a key for, with the right MAC, signed for this daemon, with a fresh stamp
// and a new counter, is heard; and nothing a stranger sends can lock a real operator out.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/lcm_bridge/message_authenticator.hpp"
#include "hsa/command_t.hpp"
#include "hsa/setpoint_t.hpp"
#include "msgs/auth/message_mac.hpp"
#include "msgs/auth/status_mac.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t kStart = 1'800'000'000'000'000;  // hsad's start, µs on the wall clock
constexpr std::int64_t kNow = kStart + 60'000'000;
constexpr std::int64_t kInstance = 0x0123'4567'89ab'cdef;  // this hsad's start
const std::string kSystem = "rig-a";
const std::string kCommands = "HSA/x/COMMAND";
const std::string kSetpoints = "HSA/x/SETPOINT";

msgs::Key key_of(unsigned char first) {
  msgs::Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<unsigned char>(first + 3 * i);
  return k;
}

AuthConfig two_operators() {
  AuthConfig c;
  c.keys = {{"bob", key_of(2)}, {"alice", key_of(1)}};  // any order
  c.stamp_window_s = 2.0;
  c.system = kSystem;
  c.instance = kInstance;
  return c;
}

// A signed message and the bytes it travels as.
template <typename Message>
struct Sent {
  Message msg;
  std::vector<std::uint8_t> bytes;
};

Sent<hsa::command_t> command(const std::string& op, const msgs::Key& key, std::int64_t counter,
                             std::int64_t stamp_us = kNow, const std::string& channel = kCommands,
                             const std::string& system = kSystem, std::int64_t instance = kInstance) {
  Sent<hsa::command_t> s{};
  s.msg.command = hsa::command_t::ENABLE;
  s.msg.system = system;
  s.msg.instance = instance;
  s.msg.operator_id = op;
  s.msg.counter = counter;
  s.msg.stamp_us = stamp_us;
  s.bytes = msgs::encode_signed(s.msg, key, channel);
  return s;
}

template <typename Message>
RejectReason check(const MessageAuthenticator& auth, MessageAuthenticator::Channel& channel, const Sent<Message>& s,
                   std::int64_t now = kNow) {
  return auth.check(channel, s.msg, s.bytes.data(), s.bytes.size(), now);
}

TEST(MessageAuthenticator, AcceptsAKnownOperatorsSignedFreshMessage) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 10)), RejectReason::none);
  EXPECT_EQ(check(auth, channel, command("bob", key_of(2), 10)), RejectReason::none);
}

TEST(MessageAuthenticator, RefusesEachForgeryForItsReason) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_EQ(check(auth, channel, command("mallory", key_of(9), 10)), RejectReason::unknown_operator);
  EXPECT_EQ(check(auth, channel, command("", key_of(9), 10)), RejectReason::unknown_operator);
  // alice's name with another key.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(2), 10)), RejectReason::bad_mac);
  // Signed for another axis's channel, sent on this one.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 10, kNow, "HSA/y/COMMAND")), RejectReason::bad_mac);
  // Altered after signing.
  auto altered = command("alice", key_of(1), 10);
  altered.bytes[20] ^= 0x40;
  EXPECT_EQ(check(auth, channel, altered), RejectReason::bad_mac);
  // And the real one still goes through: none of that spent alice's counter.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 10)), RejectReason::none);
}

TEST(MessageAuthenticator, RefusesAStampOutsideTheWindowOrBeforeTheStart) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 1, kNow - 2'000'001)), RejectReason::stale_stamp);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 2, kNow + 2'000'001)), RejectReason::stale_stamp);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 3, std::numeric_limits<std::int64_t>::min())),
            RejectReason::stale_stamp);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 4, std::numeric_limits<std::int64_t>::max())),
            RejectReason::stale_stamp);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 5, kNow - 2'000'000)), RejectReason::none);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 6, kNow + 2'000'000)), RejectReason::none);
  // Just after a start, a message stamped before it (a capture from the daemon's previous run) is
  // refused although it is inside the window.
  const MessageAuthenticator restarted(two_operators(), kNow);
  auto fresh = restarted.channel(kCommands);
  EXPECT_EQ(check(restarted, fresh, command("alice", key_of(1), 7, kNow - 1)), RejectReason::stale_stamp);
  EXPECT_EQ(check(restarted, fresh, command("alice", key_of(1), 8, kNow)), RejectReason::none);
}

TEST(MessageAuthenticator, ACounterIsAcceptedOncePerOperatorAndChannel) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto commands = auth.channel(kCommands);
  auto setpoints = auth.channel(kSetpoints);
  const auto first = command("alice", key_of(1), 100);
  EXPECT_EQ(check(auth, commands, first), RejectReason::none);
  EXPECT_EQ(check(auth, commands, first), RejectReason::replay);                       // the same bytes
  EXPECT_EQ(check(auth, commands, command("alice", key_of(1), 99)), RejectReason::replay);  // an older one
  EXPECT_EQ(check(auth, commands, command("alice", key_of(1), 101)), RejectReason::none);
  // bob and the setpoint channel keep their own counters.
  EXPECT_EQ(check(auth, commands, command("bob", key_of(2), 5)), RejectReason::none);
  Sent<hsa::setpoint_t> sp{};
  sp.msg.operator_id = "alice";
  sp.msg.system = kSystem;
  sp.msg.instance = kInstance;
  sp.msg.counter = 50;
  sp.msg.stamp_us = kNow;
  sp.bytes = msgs::encode_signed(sp.msg, key_of(1), kSetpoints);
  EXPECT_EQ(check(auth, setpoints, sp), RejectReason::none);
}

TEST(MessageAuthenticator, AForgedHugeCounterCannotLockTheOperatorOut) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(7), std::numeric_limits<std::int64_t>::max())),
            RejectReason::bad_mac);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 1, kNow - 10'000'000)), RejectReason::stale_stamp);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 2)), RejectReason::none);
}

TEST(MessageAuthenticator, RefusesAnAuthenticMessageSignedForAnotherDaemon) {
  const MessageAuthenticator auth(two_operators(), kStart);
  auto channel = auth.channel(kCommands);
  // alice's own, signed with her key, but for another rig, another start of this one, or none.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 10, kNow, kCommands, "rig-b")), RejectReason::wrong_daemon);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 11, kNow, kCommands, kSystem, kInstance + 1)),
            RejectReason::wrong_daemon);
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 12, kNow, kCommands, "", 0)), RejectReason::wrong_daemon);
  // Relayed long after it was sent, it is still counted as relayed.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 13, kNow - 10'000'000, kCommands, "rig-b")),
            RejectReason::wrong_daemon);
  // A stranger's is a bad MAC, whatever it claims to be for.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(9), 14, kNow, kCommands, "rig-b")), RejectReason::bad_mac);
  // None of those spent alice's counter.
  EXPECT_EQ(check(auth, channel, command("alice", key_of(1), 10)), RejectReason::none);
}

TEST(MessageAuthenticator, DrawsANewInstanceAtEachStart) {
  AuthConfig c = two_operators();
  c.instance = 0;
  const MessageAuthenticator first(c, kStart);
  const MessageAuthenticator second(c, kStart);
  EXPECT_GT(first.instance(), 0);
  EXPECT_GT(second.instance(), 0);
  EXPECT_NE(first.instance(), second.instance());  // 2^-63 to fail by chance
  EXPECT_EQ(first.system(), kSystem);
  auto channel = first.channel(kCommands);
  EXPECT_EQ(check(first, channel, command("alice", key_of(1), 1, kNow, kCommands, kSystem, second.instance())),
            RejectReason::wrong_daemon);
  EXPECT_EQ(check(first, channel, command("alice", key_of(1), 2, kNow, kCommands, kSystem, first.instance())),
            RejectReason::none);
}

TEST(MessageAuthenticator, OffItAcceptsUnboundMessagesButNotThoseBoundToAnotherDaemon) {
  AuthConfig off;
  off.required = false;
  off.system = kSystem;
  off.instance = kInstance;
  const MessageAuthenticator auth(off, kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_EQ(check(auth, channel, command("", msgs::Key{}, 0, 0, kCommands, "", 0)), RejectReason::none);
  EXPECT_EQ(check(auth, channel, command("", msgs::Key{}, 0, 0, kCommands, "elsewhere", 0)), RejectReason::none);
  EXPECT_EQ(check(auth, channel, command("", msgs::Key{}, 0, 0)), RejectReason::none);
  EXPECT_EQ(check(auth, channel, command("", msgs::Key{}, 0, 0, kCommands, kSystem, kInstance + 1)),
            RejectReason::wrong_daemon);
  EXPECT_EQ(check(auth, channel, command("", msgs::Key{}, 0, 0, kCommands, "rig-b", kInstance)),
            RejectReason::wrong_daemon);
}

TEST(MessageAuthenticator, OffItAcceptsUnsignedMessages) {
  AuthConfig off;
  off.required = false;
  const MessageAuthenticator auth(off, kStart);
  auto channel = auth.channel(kCommands);
  EXPECT_FALSE(auth.required());
  const auto unsigned_message = command("", msgs::Key{}, 0, 0, kCommands, "", 0);
  EXPECT_EQ(check(auth, channel, unsigned_message), RejectReason::none);
  EXPECT_EQ(check(auth, channel, unsigned_message), RejectReason::none);
}

TEST(MessageAuthenticator, RequiredWithoutKeysOrWithABadWindowIsRefused) {
  EXPECT_THROW(MessageAuthenticator(AuthConfig{}, kStart), std::invalid_argument);
  AuthConfig c = two_operators();
  c.stamp_window_s = 0.0;
  EXPECT_THROW(MessageAuthenticator(c, kStart), std::invalid_argument);
  c.stamp_window_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(MessageAuthenticator(c, kStart), std::invalid_argument);
  c = two_operators();
  c.keys.push_back({"alice", key_of(5)});
  EXPECT_THROW(MessageAuthenticator(c, kStart), std::invalid_argument);
  // Each status is signed for every key: their number is bounded.
  c = two_operators();
  c.keys.clear();
  for (std::size_t i = 0; i <= msgs::kMaxStatusMacs; ++i) c.keys.push_back({"op" + std::to_string(i), key_of(1)});
  EXPECT_THROW(MessageAuthenticator(c, kStart), std::invalid_argument);
  c.keys.pop_back();
  EXPECT_NO_THROW(MessageAuthenticator(c, kStart));
}

}  // namespace
}  // namespace hsa::daemon
