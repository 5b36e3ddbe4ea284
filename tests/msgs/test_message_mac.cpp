// The MAC of a setpoint or command (msgs/auth/message_mac.hpp): standard HMAC-SHA-256, so any
// client with a standard library can sign, over every byte that matters.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "hsa/command_t.hpp"
#include "hsa/setpoint_t.hpp"
#include "msgs/auth/message_mac.hpp"
#include "tests/msgs/test_key_support.hpp"

namespace hsa::msgs {
namespace {

hsa::command_t enable_command() {
  hsa::command_t c{};
  c.utime = 1;
  c.seq = 7;
  c.command = hsa::command_t::ENABLE;
  c.operator_id = "alice";
  c.counter = 1'700'000'000'000'000'000;
  c.stamp_us = 1'700'000'000'000'000;
  return c;
}

TEST(MessageMac, IsHmacSha256OverTheChannelANulAndTheBytes) {
  // The reference is Python's hmac module (hmac.new(bytes(range(32)), b"HSA/x/COMMAND\0abc",
  // hashlib.sha256)): an implementation independent of libsodium, as a client's would be.
  const std::string bytes = "abc";
  EXPECT_EQ(hex(message_mac(key_of(0), "HSA/x/COMMAND", bytes.data(), bytes.size())),
            "24bd1164fd1de3184c39b5f1dd975af80bedc8fc76fd58787a40d77a8a798750");
}

TEST(MessageMac, ASignedMessageVerifiesAndCarriesItsMacAtTheEnd) {
  hsa::command_t c = enable_command();
  const std::vector<std::uint8_t> bytes = encode_signed(c, key_of(1), "HSA/x/COMMAND");
  EXPECT_TRUE(mac_matches(key_of(1), "HSA/x/COMMAND", bytes.data(), bytes.size()));
  EXPECT_EQ(0, std::memcmp(bytes.data() + bytes.size() - kMacBytes, c.mac, kMacBytes));
  // The bytes decode to the message that was signed, MAC included.
  hsa::command_t back{};
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(back.operator_id, "alice");
  EXPECT_EQ(back.counter, c.counter);
  EXPECT_EQ(0, std::memcmp(back.mac, c.mac, kMacBytes));
}

TEST(MessageMac, EveryByteIsCovered) {
  hsa::setpoint_t s{};
  s.position_m = 0.12;
  s.operator_id = "alice";
  s.counter = 5;
  s.stamp_us = 6;
  const std::vector<std::uint8_t> bytes = encode_signed(s, key_of(1), "HSA/x/SETPOINT");
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::vector<std::uint8_t> altered = bytes;
    altered[i] ^= 0x01;
    EXPECT_FALSE(mac_matches(key_of(1), "HSA/x/SETPOINT", altered.data(), altered.size())) << "byte " << i;
  }
}

TEST(MessageMac, AnotherKeyOrChannelDoesNotVerify) {
  hsa::command_t c = enable_command();
  const std::vector<std::uint8_t> bytes = encode_signed(c, key_of(1), "HSA/x/COMMAND");
  EXPECT_FALSE(mac_matches(key_of(2), "HSA/x/COMMAND", bytes.data(), bytes.size()));
  // The same bytes replayed on another axis's channel.
  EXPECT_FALSE(mac_matches(key_of(1), "HSA/y/COMMAND", bytes.data(), bytes.size()));
  EXPECT_FALSE(mac_matches(key_of(1), "HSA/x/COMMAN", bytes.data(), bytes.size()));
}

TEST(MessageMac, TruncatedOrMissingBytesDoNotVerify) {
  hsa::command_t c = enable_command();
  const std::vector<std::uint8_t> bytes = encode_signed(c, key_of(1), "HSA/x/COMMAND");
  EXPECT_FALSE(mac_matches(key_of(1), "HSA/x/COMMAND", bytes.data(), bytes.size() - 1));
  EXPECT_FALSE(mac_matches(key_of(1), "HSA/x/COMMAND", bytes.data(), kMacBytes - 1));
  EXPECT_FALSE(mac_matches(key_of(1), "HSA/x/COMMAND", nullptr, 0));
}

}  // namespace
}  // namespace hsa::msgs
