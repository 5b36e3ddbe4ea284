// The MAC that authenticates a setpoint_t or command_t: HMAC-SHA-256 (RFC 2104, libsodium's
// crypto_auth_hmacsha256) with the operator's key over
//
//     channel name ‖ 0x00 ‖ the message's LCM encoding up to, not including, its `mac` field.
//
// `mac` is the last field of both types and a fixed 32-byte array, so it is the last 32 bytes of
// the encoding and everything before it (fingerprint, operator id, counter, stamp and every value)
// is covered. The channel name is covered so that a message for one axis cannot be replayed on
// another. Freshness (counter, stamp) is the receiver's business: message_authenticator in hsad.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "msgs/auth/operator_key.hpp"

namespace hsa::msgs {

inline constexpr std::size_t kMacBytes = 32;
using Mac = std::array<unsigned char, kMacBytes>;

// The MAC of a message whose encoding (without the MAC) is `covered`.
[[nodiscard]] Mac message_mac(const Key& key, std::string_view channel, const void* covered, std::size_t covered_size);

// True when the last kMacBytes of `encoded` are the MAC of the bytes before them (compared in
// constant time). False for an encoding shorter than a MAC.
[[nodiscard]] bool mac_matches(const Key& key, std::string_view channel, const void* encoded, std::size_t size);

// Encodes `msg` (a setpoint_t or command_t whose operator_id, counter and stamp_us are set) and
// signs it: returns the bytes to publish, with the MAC in place, and leaves it in msg.mac too.
template <typename LcmMessage>
[[nodiscard]] std::vector<std::uint8_t> encode_signed(LcmMessage& msg, const Key& key, std::string_view channel) {
  static_assert(sizeof(msg.mac) == kMacBytes, "the MAC is the message's last field, 32 bytes");
  std::memset(msg.mac, 0, sizeof msg.mac);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  const Mac mac = message_mac(key, channel, bytes.data(), bytes.size() - kMacBytes);
  std::memcpy(bytes.data() + bytes.size() - kMacBytes, mac.data(), kMacBytes);
  std::memcpy(msg.mac, mac.data(), kMacBytes);
  return bytes;
}

}  // namespace hsa::msgs
