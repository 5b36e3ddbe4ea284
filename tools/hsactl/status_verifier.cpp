#include "tools/hsactl/status_verifier.hpp"

#include <numeric>
#include <utility>

#include "msgs/auth/status_mac.hpp"
#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

StatusVerifier::StatusVerifier(std::optional<msgs::OperatorKey> key, double window_s)
    : key_(std::move(key)), window_us_(static_cast<std::int64_t>(window_s * 1e6)) {}

bool StatusVerifier::authentic(const hsa::status_t& s, std::string_view channel, std::int64_t now_us) const {
  // Written so that no subtraction can overflow, whatever stamp_us says.
  return key_ && msgs::verify_status(s, *key_, channel) == msgs::StatusMacCheck::verified &&
         s.stamp_us >= now_us - window_us_ && s.stamp_us <= now_us + window_us_;
}

bool StatusVerifier::judge(const hsa::status_t& s, std::string_view channel, std::int64_t now_us) {
  if (!key_) return false;
  std::optional<Failure> why;
  const msgs::StatusMacCheck mac = msgs::verify_status(s, *key_, channel);
  if (mac == msgs::StatusMacCheck::bad_mac) {
    why = Failure::bad_mac;
  } else if (mac == msgs::StatusMacCheck::no_mac_for_operator) {
    why = Failure::no_mac_for_me;
  } else if (daemon_ && (s.system != daemon_->system || s.instance != daemon_->instance)) {
    why = Failure::other_daemon;
  } else if (s.stamp_us < now_us - window_us_ || s.stamp_us > now_us + window_us_ || s.stamp_us < last_stamp_us_) {
    why = Failure::old_stamp;
  }
  if (why) {
    ++failed_[static_cast<std::size_t>(*why)];
    ++claimed_[s.state];
    return false;
  }
  if (!daemon_) daemon_ = Daemon{s.system, s.instance};
  last_stamp_us_ = s.stamp_us;
  return true;
}

std::uint64_t StatusVerifier::failed() const { return std::accumulate(failed_.begin(), failed_.end(), std::uint64_t{0}); }

std::string StatusVerifier::failures() const {
  const std::uint64_t n = failed();
  if (n == 0) return "";
  static constexpr std::array<const char*, kFailureCount> kWhy = {"bad MAC", "no MAC for this operator",
                                                                  "from another daemon", "old stamp"};
  std::string out = std::to_string(n) + (n == 1 ? " status message" : " status messages") + " that failed verification (";
  bool first = true;
  for (std::size_t i = 0; i < kFailureCount; ++i) {
    if (failed_[i] == 0) continue;
    out += (first ? "" : ", ") + std::to_string(failed_[i]) + " " + kWhy[i];
    first = false;
  }
  out += n == 1 ? "); it claimed " : "); they claimed ";
  first = true;
  for (const auto& [state, count] : claimed_) {
    out += (first ? "" : ", ") + std::string(state_name(state)) + (n == 1 ? "" : " (" + std::to_string(count) + ")");
    first = false;
  }
  return out;
}

}  // namespace hsa::ctl
