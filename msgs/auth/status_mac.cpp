#include "msgs/auth/status_mac.hpp"

#include <sodium.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace hsa::msgs {

namespace {

// The bytes a status's MACs cover: its encoding with no MACs.
std::vector<std::uint8_t> covered_encoding(hsa::status_t& unsigned_msg) {
  unsigned_msg.num_macs = 0;
  unsigned_msg.mac_operator.clear();
  unsigned_msg.mac.clear();
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(unsigned_msg.getEncodedSize()));
  unsigned_msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

}  // namespace

Mac status_mac(const Key& key, std::string_view channel, std::string_view operator_id, const void* covered,
               std::size_t covered_size) {
  // message_mac covers channel ‖ 0 ‖ its bytes: here the bytes are operator id ‖ 0 ‖ the encoding.
  std::vector<unsigned char> bytes(operator_id.begin(), operator_id.end());
  bytes.push_back(0);
  const auto* encoding = static_cast<const unsigned char*>(covered);
  bytes.insert(bytes.end(), encoding, encoding + covered_size);
  return message_mac(key, channel, bytes.data(), bytes.size());
}

void sign_status(hsa::status_t& msg, const std::vector<OperatorKey>& keys, std::string_view channel) {
  if (keys.size() > kMaxStatusMacs) {
    throw std::invalid_argument("a status is signed for at most " + std::to_string(kMaxStatusMacs) +
                                " operator keys, not " + std::to_string(keys.size()));
  }
  const std::vector<std::uint8_t> covered = covered_encoding(msg);
  msg.num_macs = static_cast<std::int16_t>(keys.size());
  msg.mac_operator.reserve(keys.size());
  msg.mac.reserve(keys.size());
  for (const OperatorKey& k : keys) {
    const Mac mac = status_mac(k.key, channel, k.operator_id, covered.data(), covered.size());
    msg.mac_operator.push_back(k.operator_id);
    msg.mac.emplace_back(mac.begin(), mac.end());
  }
}

StatusMacCheck verify_status(const hsa::status_t& msg, const OperatorKey& key, std::string_view channel) {
  std::size_t found = msg.mac_operator.size();
  for (std::size_t i = 0; i < msg.mac_operator.size(); ++i) {
    if (msg.mac_operator[i] == key.operator_id) {
      found = i;
      break;
    }
  }
  if (found == msg.mac_operator.size() || found >= msg.mac.size() || msg.mac[found].size() != kMacBytes) {
    return StatusMacCheck::no_mac_for_operator;
  }
  hsa::status_t copy = msg;
  const std::vector<std::uint8_t> covered = covered_encoding(copy);
  const Mac expected = status_mac(key.key, channel, key.operator_id, covered.data(), covered.size());
  return crypto_verify_32(expected.data(), reinterpret_cast<const unsigned char*>(msg.mac[found].data())) == 0
             ? StatusMacCheck::verified
             : StatusMacCheck::bad_mac;
}

}  // namespace hsa::msgs
