// Which status hsactl believes (tools/hsactl/status_verifier.hpp): only one signed by hsad for this
// operator, from the daemon it first verified, stamped now and not older than the last one.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "msgs/auth/status_mac.hpp"
#include "tools/hsactl/status_verifier.hpp"

namespace hsa::ctl {
namespace {

constexpr std::int64_t kNow = 1'800'000'000'000'000;
constexpr const char* kChannel = "HSA/lift/STATUS";

msgs::Key key_of(unsigned char first) {
  msgs::Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<unsigned char>(first + 5 * i);
  return k;
}

const msgs::OperatorKey kAlice{"alice", key_of(1)};
const msgs::OperatorKey kBob{"bob", key_of(2)};

hsa::status_t status(std::int8_t state, std::int64_t stamp_us = kNow, std::int64_t instance = 7,
                     const std::string& system = "rig-a", const msgs::Key& key = kAlice.key,
                     const char* channel = kChannel) {
  hsa::status_t s{};
  s.state = state;
  s.system = system;
  s.instance = instance;
  s.stamp_us = stamp_us;
  msgs::sign_status(s, {{"alice", key}, kBob}, channel);
  return s;
}

TEST(StatusVerifier, BelievesHsadsStatusAndLearnsTheDaemon) {
  StatusVerifier v(kAlice, 2.0);
  EXPECT_FALSE(v.daemon());
  EXPECT_TRUE(v.judge(status(hsa::status_t::STATE_DISABLED), kChannel, kNow + 1'000'000));
  ASSERT_TRUE(v.daemon());
  EXPECT_EQ(v.daemon()->system, "rig-a");
  EXPECT_EQ(v.daemon()->instance, 7);
  EXPECT_TRUE(v.judge(status(hsa::status_t::STATE_ENABLED, kNow + 100), kChannel, kNow));
  EXPECT_EQ(v.failed(), 0u);
  EXPECT_EQ(v.failures(), "");
}

TEST(StatusVerifier, CountsWhatItDoesNotBelieveWithWhatItClaimed) {
  StatusVerifier v(kAlice, 2.0);
  // A forger without alice's key: a MAC under her name that does not match, or none for her.
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED, kNow, 7, "rig-a", key_of(9)), kChannel, kNow));
  hsa::status_t unsigned_status{};
  unsigned_status.state = hsa::status_t::STATE_DISABLED;
  EXPECT_FALSE(v.judge(unsigned_status, kChannel, kNow));
  // Another axis's status shown as this one's.
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_ENABLED, kNow, 7, "rig-a", kAlice.key, "HSA/other/STATUS"),
                       kChannel, kNow));
  // hsad's own, recorded and sent again 3 s later.
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED), kChannel, kNow + 3'000'000));
  EXPECT_FALSE(v.daemon());  // nothing believed, nothing learned
  EXPECT_EQ(v.failed(), 4u);
  EXPECT_EQ(v.failed(StatusVerifier::Failure::bad_mac), 2u);
  EXPECT_EQ(v.failed(StatusVerifier::Failure::no_mac_for_me), 1u);
  EXPECT_EQ(v.failed(StatusVerifier::Failure::old_stamp), 1u);
  EXPECT_EQ(v.failures(), "4 status messages that failed verification (2 bad MAC, 1 no MAC for this operator, 1 old "
                          "stamp); they claimed DISABLED (3), ENABLED (1)");
}

TEST(StatusVerifier, OnceItKnowsTheDaemonItRefusesAnotherAndOlderStatus) {
  StatusVerifier v(kAlice, 2.0);
  ASSERT_TRUE(v.judge(status(hsa::status_t::STATE_ENABLED, kNow), kChannel, kNow));
  // Another rig signed with the same key, or hsad restarted: not the daemon commands are signed for.
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED, kNow + 10, 8), kChannel, kNow));
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED, kNow + 10, 7, "rig-b"), kChannel, kNow));
  EXPECT_EQ(v.failed(StatusVerifier::Failure::other_daemon), 2u);
  // A genuine status from before the last one believed, sent again: it would turn the clock back.
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED, kNow - 500'000), kChannel, kNow));
  EXPECT_EQ(v.failed(StatusVerifier::Failure::old_stamp), 1u);
  EXPECT_TRUE(v.judge(status(hsa::status_t::STATE_ENABLED, kNow + 20), kChannel, kNow));
}

TEST(StatusVerifier, WithoutAKeyNothingIsVerified) {
  StatusVerifier v(std::nullopt, 2.0);
  EXPECT_FALSE(v.can_verify());
  EXPECT_FALSE(v.judge(status(hsa::status_t::STATE_DISABLED), kChannel, kNow));
  EXPECT_FALSE(v.authentic(status(hsa::status_t::STATE_DISABLED), kChannel, kNow));
}

TEST(StatusVerifier, AnotherAxissStatusIsJudgedOnItsMacAndStampAlone) {
  StatusVerifier v(kAlice, 2.0);
  ASSERT_TRUE(v.judge(status(hsa::status_t::STATE_ENABLED, kNow, 7), kChannel, kNow));
  const char* other = "HSA/other/STATUS";
  EXPECT_TRUE(v.authentic(status(hsa::status_t::STATE_DISABLED, kNow, 99, "rig-b", kAlice.key, other), other, kNow));
  EXPECT_FALSE(v.authentic(status(hsa::status_t::STATE_DISABLED, kNow, 99, "rig-b", key_of(9), other), other, kNow));
  EXPECT_FALSE(v.authentic(status(hsa::status_t::STATE_DISABLED, kNow - 3'000'000, 7, "rig-a", kAlice.key, other),
                           other, kNow));
}

}  // namespace
}  // namespace hsa::ctl
