// Authentication of incoming setpoints and commands, on the LCM thread.
//
// A message is accepted only when, in this order:
//   1. its operator_id names a key hsad holds (else unknown_operator);
//   2. its MAC matches (msgs/auth/message_mac.hpp: HMAC-SHA-256 over the channel name and the
//      whole encoding) (else bad_mac);
//   3. it is signed for this daemon: its system is hsad's [auth] system_name and its instance
//      this start's random identity, which the sender learned from a verified status (else
//      wrong_daemon);
//   4. its stamp_us lies within ±stamp_window of hsad's wall clock and not before hsad started
//      (else stale_stamp);
//   5. its counter is above the last counter accepted from that operator on that channel (else
//      replay); the counter then becomes the last.
// 1 and 2 stop forged, altered and re-addressed messages (the channel is under the MAC). 3 stops a
// message relayed to another hsad that holds the same operator's key (another rig in the lab), and
// a message captured before a restart: the counters live in memory only, and the instance is new
// at every start. 5 stops a captured message from being sent again; 4 bounds how long one lives.
// 3 comes right after the MAC, so a stranger's message is counted as bad_mac, never as
// wrong_daemon, and a relayed one is counted as relayed whatever its age.
//
// Without authentication (require_auth = false) only 3 is judged, and a message with instance 0
// (an unbound sender, which could not learn the instance from a signed status) is accepted; one
// bound to another instance is still refused.
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
  std::vector<msgs::OperatorKey> keys;  // the operators hsad obeys (and signs status for); at least
                                        // one when required, at most msgs::kMaxStatusMacs
  double stamp_window_s = 2.0;          // how far a sender's clock may be from hsad's, s
  std::string system;                   // [auth] system_name: a message must name it
  std::int64_t instance = 0;            // this start's identity; 0: the authenticator draws one
};

class MessageAuthenticator {
 public:
  // Throws std::invalid_argument when authentication is required and there is no key, or for a
  // window that is not a positive finite number. `start_us`: hsad's start on the wall clock.
  MessageAuthenticator(AuthConfig config, std::int64_t start_us);

  [[nodiscard]] bool required() const { return config_.required; }
  [[nodiscard]] const std::vector<msgs::OperatorKey>& keys() const { return config_.keys; }
  [[nodiscard]] const std::string& system() const { return config_.system; }
  // Random, 1 to 2^63 - 1, new at every start (libsodium's randombytes) unless the configuration set one.
  [[nodiscard]] std::int64_t instance() const { return config_.instance; }

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
  // exactly into `msg`), `now_us` hsad's wall clock. RejectReason::none when accepted. Without
  // authentication, only an unbound message (instance 0) or one bound to this daemon passes.
  template <typename LcmMessage>
  [[nodiscard]] RejectReason check(Channel& channel, const LcmMessage& msg, const void* data, std::size_t size,
                                   std::int64_t now_us) const {
    return check(channel, {msg.operator_id, msg.system, msg.instance, msg.counter, msg.stamp_us}, data, size, now_us);
  }

 private:
  struct Claims {  // what a message says about itself, under its MAC
    std::string_view operator_id;
    std::string_view system;
    std::int64_t instance;
    std::int64_t counter;
    std::int64_t stamp_us;
  };
  RejectReason check(Channel& channel, const Claims& claims, const void* data, std::size_t size,
                     std::int64_t now_us) const;
  [[nodiscard]] bool for_this_daemon(const Claims& claims) const;

  AuthConfig config_;  // keys sorted by operator id
  std::int64_t window_us_;
  std::int64_t start_us_;
};

// The wall clock (CLOCK_REALTIME) in µs since 1970: the clock senders stamp stamp_us with.
[[nodiscard]] std::int64_t wall_clock_us();

}  // namespace hsa::daemon
