#include "daemon/lcm_bridge/message_authenticator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <sodium.h>

#include "msgs/auth/message_mac.hpp"
#include "msgs/auth/status_mac.hpp"

namespace hsa::daemon {

namespace {

// 63 random bits, never 0 (0 is an unbound sender's instance).
std::int64_t new_instance() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium did not initialize: no random instance");
  std::uint64_t bits = 0;
  while ((bits & INT64_MAX) == 0) randombytes_buf(&bits, sizeof bits);
  return static_cast<std::int64_t>(bits & INT64_MAX);
}

}  // namespace

MessageAuthenticator::MessageAuthenticator(AuthConfig config, std::int64_t start_us)
    : config_(std::move(config)), window_us_(0), start_us_(start_us) {
  if (config_.required && config_.keys.empty()) {
    throw std::invalid_argument("authentication is required but hsad holds no operator key");
  }
  if (config_.keys.size() > msgs::kMaxStatusMacs) {
    throw std::invalid_argument(std::to_string(config_.keys.size()) + " operator keys: hsad signs each status for "
                                "every key it holds, at most " + std::to_string(msgs::kMaxStatusMacs));
  }
  if (config_.instance < 0) throw std::invalid_argument("the instance must not be negative");
  if (config_.instance == 0) config_.instance = new_instance();
  if (!std::isfinite(config_.stamp_window_s) || config_.stamp_window_s <= 0.0 || config_.stamp_window_s > 3600.0) {
    throw std::invalid_argument("stamp_window_s must be within (0, 3600] s");
  }
  window_us_ = static_cast<std::int64_t>(config_.stamp_window_s * 1e6);
  std::sort(config_.keys.begin(), config_.keys.end(),
            [](const auto& a, const auto& b) { return a.operator_id < b.operator_id; });
  const auto same_id = [](const auto& a, const auto& b) { return a.operator_id == b.operator_id; };
  if (std::adjacent_find(config_.keys.begin(), config_.keys.end(), same_id) != config_.keys.end()) {
    throw std::invalid_argument("two keys for one operator");
  }
}

bool MessageAuthenticator::for_this_daemon(const Claims& claims) const {
  return claims.instance == config_.instance && claims.system == config_.system;
}

RejectReason MessageAuthenticator::check(Channel& channel, const Claims& claims, const void* data, std::size_t size,
                                         std::int64_t now_us) const {
  if (!config_.required) {
    return claims.instance == 0 || for_this_daemon(claims) ? RejectReason::none : RejectReason::wrong_daemon;
  }
  const auto key = std::lower_bound(config_.keys.begin(), config_.keys.end(), claims.operator_id,
                                    [](const msgs::OperatorKey& k, std::string_view id) { return k.operator_id < id; });
  if (key == config_.keys.end() || key->operator_id != claims.operator_id) return RejectReason::unknown_operator;
  if (!msgs::mac_matches(key->key, channel.name(), data, size)) return RejectReason::bad_mac;
  if (!for_this_daemon(claims)) return RejectReason::wrong_daemon;
  // Written so that no subtraction can overflow, whatever stamp_us says.
  const std::int64_t stamp_us = claims.stamp_us;
  if (stamp_us < start_us_ || stamp_us < now_us - window_us_ || stamp_us > now_us + window_us_) {
    return RejectReason::stale_stamp;
  }
  std::int64_t& last = channel.last_counter_[static_cast<std::size_t>(key - config_.keys.begin())];
  if (claims.counter <= last) return RejectReason::replay;
  last = claims.counter;
  return RejectReason::none;
}

std::int64_t wall_clock_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace hsa::daemon
