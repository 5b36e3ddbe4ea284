// Which status hsactl believes. Anyone on the LAN can publish on HSA/<axis>/STATUS, so hsactl
// takes a status for hsad's word only when, in this order:
//   1. it carries a MAC under this operator's id that this operator's key verifies
//      (msgs/auth/status_mac.hpp; else bad_mac or no_mac_for_me);
//   2. it comes from the daemon hsactl is talking to: the system and instance of the first status
//      it verified (else other_daemon: another rig, or hsad restarted meanwhile);
//   3. its stamp is within ±window of this host's wall clock and not older than the last status
//      believed (else old_stamp: a status recorded and sent again).
// Everything else is counted by reason, with the state it claimed, so that hsactl can say what it
// received and did not believe. Without a key nothing can be verified: can_verify() is false, and
// hsactl says so with every answer it shows.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "hsa/status_t.hpp"
#include "msgs/auth/operator_key.hpp"

namespace hsa::ctl {

class StatusVerifier {
 public:
  enum class Failure { bad_mac, no_mac_for_me, other_daemon, old_stamp };
  static constexpr std::size_t kFailureCount = 4;

  // The daemon a verified status came from: what commands are then signed for.
  struct Daemon {
    std::string system;
    std::int64_t instance = 0;
  };

  StatusVerifier(std::optional<msgs::OperatorKey> key, double window_s);

  [[nodiscard]] bool can_verify() const { return key_.has_value(); }
  [[nodiscard]] const std::optional<msgs::OperatorKey>& key() const { return key_; }

  // Judges `s`, received on `channel` at `now_us` (this host's wall clock, µs since 1970): true
  // when it is to be believed (and then its daemon is learned, if it was not yet). Always false
  // without a key.
  bool judge(const hsa::status_t& s, std::string_view channel, std::int64_t now_us);
  // The MAC and the stamp window only (1 and the window of 3): for another axis's status, whose
  // daemon need not be this axis's.
  [[nodiscard]] bool authentic(const hsa::status_t& s, std::string_view channel, std::int64_t now_us) const;

  [[nodiscard]] const std::optional<Daemon>& daemon() const { return daemon_; }
  [[nodiscard]] std::uint64_t failed() const;
  [[nodiscard]] std::uint64_t failed(Failure why) const { return failed_[static_cast<std::size_t>(why)]; }
  // "3 status messages failed verification (2 bad MAC, 1 old stamp); they claimed DISABLED (2), ENABLED (1)",
  // or "" when none did.
  [[nodiscard]] std::string failures() const;

 private:
  std::optional<msgs::OperatorKey> key_;
  std::int64_t window_us_;
  std::optional<Daemon> daemon_;
  std::int64_t last_stamp_us_ = 0;
  std::array<std::uint64_t, kFailureCount> failed_{};
  std::map<std::int8_t, std::uint64_t> claimed_;  // state claimed by the failed ones
};

}  // namespace hsa::ctl
