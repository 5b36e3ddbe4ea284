// How hsad signs an axis's status and how a client verifies it: HMAC-SHA-256 (libsodium, the
// primitive of message_mac.hpp) with each operator's own key over
//
//     channel name ‖ 0x00 ‖ operator id ‖ 0x00 ‖ the status's LCM encoding with num_macs = 0
//
// (and mac_operator, mac empty). hsad holds every operator's key already, so signing with them
// needs no new key to hand out, and a leaked key lets its thief forge status only to that one
// operator. hsad signs once per key it holds (at most kMaxStatusMacs); an operator checks the MAC
// under its own id. LCM's encoding is deterministic, so the verifier re-encodes what it decoded.
// The channel is covered so that one axis's status cannot be shown as another's, the operator id
// so that one operator's MAC cannot be passed off under another's name.
//
// Freshness and origin (stamp_us, system, instance) are the verifier's to judge: this says only
// whether hsad, holding this key, said these bytes.
#pragma once

#include <cstddef>
#include <string_view>
#include <vector>

#include "hsa/status_t.hpp"
#include "msgs/auth/message_mac.hpp"
#include "msgs/auth/operator_key.hpp"

namespace hsa::msgs {

// The most keys hsad signs each status for: 64 MACs add about 4.5 kB to a status and 64 HMACs
// (under 1 ms) to each publication; a larger key folder is refused at start.
inline constexpr std::size_t kMaxStatusMacs = 64;

// The MAC of a status for `operator_id`, whose encoding with num_macs = 0 is `covered`.
[[nodiscard]] Mac status_mac(const Key& key, std::string_view channel, std::string_view operator_id,
                             const void* covered, std::size_t covered_size);

// Replaces msg's MACs by one per key, in the keys' order. Throws std::invalid_argument for more
// than kMaxStatusMacs keys.
void sign_status(hsa::status_t& msg, const std::vector<OperatorKey>& keys, std::string_view channel);

enum class StatusMacCheck {
  verified,         // msg carries a MAC under key.operator_id, and it matches
  no_mac_for_operator,   // no MAC under key.operator_id (or a malformed one)
  bad_mac,          // a MAC under that id that does not match: forged or altered
};

[[nodiscard]] StatusMacCheck verify_status(const hsa::status_t& msg, const OperatorKey& key, std::string_view channel);

}  // namespace hsa::msgs
