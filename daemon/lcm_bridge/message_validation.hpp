// Validation of incoming setpoints and commands: the gate between the network and the loops.
//
// Pure functions (no I/O, no state), so every rule is testable without LCM running. A message that
// fails any rule is rejected as a whole, with one reason, and never reaches the RT thread: a NaN
// must not get into an integrator, and a half-applied command is worse than none. Only the fields
// a message uses are checked (a command's gains are ignored unless it is GAINS), and fields it
// does not use are zeroed so that nothing unchecked crosses the ring.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string_view>

#include "daemon/lcm_bridge/rt_messages.hpp"
#include "msgs/decode_exact.hpp"
#include "hsa/command_t.hpp"
#include "hsa/setpoint_t.hpp"

namespace hsa::daemon {

// X(reason): why a message was refused, in the order it is checked. The status
// counter of each is a rejected_* field of status_t (message_conversion.cpp).
#define HSA_REJECT_REASONS(X)                                                                     \
  X(decode)       /* the bytes are not a message of the expected type (hash, length) */          \
  X(non_finite)   /* NaN or ±Inf in a used field */                                             \
  X(out_of_range) /* position, speed, opening or gain outside its allowed range */              \
  X(unknown)      /* unknown command or mode */                                                 \
  /* Authentication (message_authenticator.hpp), checked before the rest. */                    \
  X(unknown_operator) /* no key for the message's operator_id */                                \
  X(bad_mac)          /* the MAC does not match: another key, or altered bytes */               \
  X(stale_stamp)      /* stamp_us outside the window, or before hsad started */                 \
  X(replay)           /* counter not above the operator's last on this channel */               \
  /* Command authority (command_lease.hpp), checked after validation. */                        \
  X(lease_held)       /* another operator holds the axis */

enum class RejectReason : std::uint8_t {
  none = 0,  // accepted
#define HSA_REJECT_ENUMERATOR(reason) reason,
  HSA_REJECT_REASONS(HSA_REJECT_ENUMERATOR)
#undef HSA_REJECT_ENUMERATOR
};
// Every reason and none, for arrays indexed by reason.
inline constexpr std::size_t kRejectReasonCount = 1
#define HSA_REJECT_COUNT(reason) +1
    HSA_REJECT_REASONS(HSA_REJECT_COUNT)
#undef HSA_REJECT_COUNT
    ;

[[nodiscard]] std::string_view to_string(RejectReason reason);

// What a setpoint for one axis may ask for. Positions are the axis's configured range (its soft
// limits, or a stricter setpoint range); the speed limit applies to the velocity feed-forward.
struct AxisLimits {
  double min_position_m = 0.0;
  double max_position_m = 0.0;
  double max_velocity_m_s = std::numeric_limits<double>::infinity();

  // Finite min < max and a positive (possibly infinite) speed limit.
  [[nodiscard]] bool valid() const;
};

// A validated message, or why not. `msg` is meaningful only when ok().
template <typename T>
struct Validated {
  RejectReason reason = RejectReason::none;
  T msg{};

  [[nodiscard]] bool ok() const { return reason == RejectReason::none; }
};

[[nodiscard]] Validated<SetpointMsg> validate_setpoint(const hsa::setpoint_t& in, const AxisLimits& limits);
[[nodiscard]] Validated<CommandMsg> validate_command(const hsa::command_t& in);

// decode_exact (msgs/decode_exact.hpp): the one way hsa decodes bytes from the network.
using msgs::decode_exact;

}  // namespace hsa::daemon
