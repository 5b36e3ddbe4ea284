// Authentication of incoming setpoints and commands, on the LCM thread.
//
// A message is accepted only when, in this order:
//   1. its operator_id names a key hsad holds (else unknown_operator);
//   2. its MAC matches (msgs/auth/message_mac.hpp: HMAC-SHA-256 over the channel name and the
//      whole encoding) (else bad_mac);
//   3. its stamp_us lies within ±stamp_window of hsad's wall clock and not before hsad started
//      (else stale_stamp);
//   4. its counter is above the last counter accepted from that operator on that channel (else
//      replay); the counter then becomes the last.
// 1 and 2 stop forged, altered and re-addressed messages (the channel is under the MAC). 4 stops a
// captured message from being sent again; the counters live in memory only, so 3 covers what 4
// cannot after a restart: a message stamped before hsad started is refused.
//
// A message that passes is authentic and fresh, but not necessarily valid: validation
// (message_validation.hpp) comes after, so an authentic out-of-range setpoint still spends its
// counter and cannot be replayed either.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "daemon/lcm_bridge/message_validation.hpp"
#include "msgs/auth/operator_key.hpp"

namespace hsa::daemon {

struct AuthConfig {
  bool required = true;                 // false only when the configuration says require_auth = false
  std::vector<msgs::OperatorKey> keys;  // the operators hsad obeys; at least one when required
  double stamp_window_s = 2.0;          // how far a sender's clock may be from hsad's, s
};

class MessageAuthenticator {
 public:
  // Throws std::invalid_argument when authentication is required and there is no key, or for a
  // window that is not a positive finite number. `start_us`: hsad's start on the wall clock.
  MessageAuthenticator(AuthConfig config, std::int64_t start_us);

  [[nodiscard]] bool required() const { return config_.required; }

  // What one channel remembers: the last accepted counter of each operator.
  class Channel {
   public:
    [[nodiscard]] const std::string& name() const { return name_; }

   private:
    friend class MessageAuthenticator;
    Channel(std::string name, std::size_t operators) : name_(std::move(name)), last_counter_(operators, kNone) {}
    static constexpr std::int64_t kNone = INT64_MIN;
    std::string name_;
    std::vector<std::int64_t> last_counter_;  // indexed like the keys
  };
  [[nodiscard]] Channel channel(std::string name) const { return Channel(std::move(name), config_.keys.size()); }

  // The checks above for one message: `data`/`size` its bytes as received (already decoded
  // exactly into `msg`), `now_us` hsad's wall clock. RejectReason::none when accepted. Always
  // none when authentication is not required.
  template <typename LcmMessage>
  [[nodiscard]] RejectReason check(Channel& channel, const LcmMessage& msg, const void* data, std::size_t size,
                                   std::int64_t now_us) const {
    return check(channel, msg.operator_id, msg.counter, msg.stamp_us, data, size, now_us);
  }

 private:
  RejectReason check(Channel& channel, std::string_view operator_id, std::int64_t counter, std::int64_t stamp_us,
                     const void* data, std::size_t size, std::int64_t now_us) const;

  AuthConfig config_;  // keys sorted by operator id
  std::int64_t window_us_;
  std::int64_t start_us_;
};

// The wall clock (CLOCK_REALTIME) in µs since 1970: the clock senders stamp stamp_us with.
[[nodiscard]] std::int64_t wall_clock_us();

}  // namespace hsa::daemon
