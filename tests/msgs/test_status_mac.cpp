// The MACs of a status (msgs/auth/status_mac.hpp): hsad signs with every operator's key, and each
// operator verifies with its own. Any field altered, another operator's key or name, another
// axis's channel: not verified.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "hsa/status_t.hpp"
#include "msgs/auth/status_mac.hpp"
#include "tests/msgs/test_key_support.hpp"
#include "msgs/decode_exact.hpp"

namespace hsa::msgs {
namespace {

const OperatorKey kAlice{"alice", key_of(1)};
const OperatorKey kBob{"bob", key_of(2)};
constexpr const char* kChannel = "HSA/x/STATUS";

hsa::status_t some_status() {
  hsa::status_t s{};
  s.utime = 123;
  s.state = hsa::status_t::STATE_DISABLED;
  s.num_faults = 1;
  s.fault_code = {hsa::status_t::FAULT_PRESSURE};
  s.fault_reason = {"pressure A over its limit"};
  s.lease_holder = "alice";
  s.num_acks = 1;
  s.ack_operator = {"alice"};
  s.ack_counter = {77};
  s.num_results = 1;
  s.result_operator = {"alice"};
  s.result_counter = {77};
  s.result_accepted = {true};
  s.result_reason = {""};
  s.num_drivers = 1;
  s.drivers.resize(1);
  s.drivers[0].name = "rig";
  s.drivers[0].state = "active";
  s.system = "rig-a";
  s.instance = 0x1234'5678'9abc'def0;
  s.stamp_us = 1'700'000'000'000'000;
  return s;
}

// What a client receives: the signed status, encoded and decoded again.
hsa::status_t on_the_wire(const hsa::status_t& signed_status) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(signed_status.getEncodedSize()));
  signed_status.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  hsa::status_t back;
  EXPECT_TRUE(decode_exact(back, bytes.data(), bytes.size()));
  return back;
}

hsa::status_t signed_status() {
  hsa::status_t s = some_status();
  sign_status(s, {kAlice, kBob}, kChannel);
  return on_the_wire(s);
}

TEST(StatusMac, IsHmacSha256OverTheChannelTheOperatorAndTheBytes) {
  // The reference is Python's hmac module (hmac.new(bytes(range(32)), b"HSA/x/STATUS\0alice\0abc",
  // hashlib.sha256)): what a client in another language computes.
  const std::string bytes = "abc";
  EXPECT_EQ(hex(status_mac(key_of(0), kChannel, "alice", bytes.data(), bytes.size())),
            "0285c6f7173684b0ad28dedaaaae3c87fce6e5ec60a513dac22929e0b5b0c1dc");
}

TEST(StatusMac, EachOperatorVerifiesWithItsOwnKey) {
  const hsa::status_t s = signed_status();
  ASSERT_EQ(s.num_macs, 2);
  EXPECT_EQ(s.mac_operator, (std::vector<std::string>{"alice", "bob"}));
  EXPECT_EQ(verify_status(s, kAlice, kChannel), StatusMacCheck::verified);
  EXPECT_EQ(verify_status(s, kBob, kChannel), StatusMacCheck::verified);
}

TEST(StatusMac, TheMacIsOverTheEncodingWithoutMacs) {
  // As msgs/README.md tells a client to compute it: encode the status with num_macs = 0.
  hsa::status_t s = signed_status();
  const std::vector<std::int8_t> alice_mac = s.mac.at(0);
  s.num_macs = 0;
  s.mac_operator.clear();
  s.mac.clear();
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(s.getEncodedSize()));
  s.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  const Mac expected = status_mac(kAlice.key, kChannel, "alice", bytes.data(), bytes.size());
  EXPECT_EQ(std::vector<std::int8_t>(expected.begin(), expected.end()), alice_mac);
}

TEST(StatusMac, AnyFieldAlteredFailsVerification) {
  const std::vector<std::pair<const char*, std::function<void(hsa::status_t&)>>> tamper = {
      {"state", [](hsa::status_t& s) { s.state = hsa::status_t::STATE_ENABLED; }},
      {"utime", [](hsa::status_t& s) { ++s.utime; }},
      {"fault reason", [](hsa::status_t& s) { s.fault_reason[0] = "none"; }},
      {"lease holder", [](hsa::status_t& s) { s.lease_holder = "mallory"; }},
      {"ack counter", [](hsa::status_t& s) { ++s.ack_counter[0]; }},
      {"result accepted", [](hsa::status_t& s) { s.result_accepted[0] = false; }},
      {"driver", [](hsa::status_t& s) { s.drivers[0].state = "error"; }},
      // A forger must not pass a frozen rod off as live, nor a live one as stale.
      {"position age", [](hsa::status_t& s) { s.position_age_us += 1; }},
      {"position stale", [](hsa::status_t& s) { s.position_stale = !s.position_stale; }},
      {"system", [](hsa::status_t& s) { s.system = "rig-b"; }},
      {"instance", [](hsa::status_t& s) { ++s.instance; }},
      {"stamp", [](hsa::status_t& s) { s.stamp_us += 1'000'000; }},
      {"alice's MAC", [](hsa::status_t& s) { s.mac[0][5] ^= 1; }},
  };
  for (const auto& [what, change] : tamper) {
    hsa::status_t s = signed_status();
    change(s);
    EXPECT_EQ(verify_status(on_the_wire(s), kAlice, kChannel), StatusMacCheck::bad_mac) << what;
  }
}

TEST(StatusMac, AnotherOperatorsKeyOrNameFailsVerification) {
  const hsa::status_t s = signed_status();
  // Bob's key under alice's name: alice's MAC does not match it.
  EXPECT_EQ(verify_status(s, {"alice", kBob.key}, kChannel), StatusMacCheck::bad_mac);
  // Bob's MAC relabelled as alice's: the operator id is covered.
  hsa::status_t relabelled = s;
  relabelled.mac_operator = {"carol", "alice"};
  EXPECT_EQ(verify_status(relabelled, {"alice", kBob.key}, kChannel), StatusMacCheck::bad_mac);
  // An operator hsad holds no key for finds no MAC for it.
  EXPECT_EQ(verify_status(s, {"carol", key_of(3)}, kChannel), StatusMacCheck::no_mac_for_operator);
  // Nor does anyone in an unsigned status.
  EXPECT_EQ(verify_status(some_status(), kAlice, kChannel), StatusMacCheck::no_mac_for_operator);
}

TEST(StatusMac, AnotherAxissChannelFailsVerification) {
  const hsa::status_t s = signed_status();
  EXPECT_EQ(verify_status(s, kAlice, "HSA/y/STATUS"), StatusMacCheck::bad_mac);
  EXPECT_EQ(verify_status(s, kAlice, "HSA/x/STATU"), StatusMacCheck::bad_mac);
}

TEST(StatusMac, MoreThanTheBoundOfKeysIsRefused) {
  std::vector<OperatorKey> keys(kMaxStatusMacs + 1, kAlice);
  hsa::status_t s = some_status();
  EXPECT_THROW(sign_status(s, keys, kChannel), std::invalid_argument);
  keys.pop_back();
  sign_status(s, keys, kChannel);
  EXPECT_EQ(s.num_macs, static_cast<std::int16_t>(kMaxStatusMacs));
}

}  // namespace
}  // namespace hsa::msgs
