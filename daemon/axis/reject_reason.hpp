// Why the LCM bridge refused a message: one table, from which the enum, its count (the port's
// counters are indexed by it) and its names derive.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

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
  X(lease_held)       /* another operator holds the axis */                                      \
  /* Authentication again, checked right after the MAC (last here only to keep the numbering). */ \
  X(wrong_daemon)     /* authentic, but signed for another daemon (system, instance) or before a restart */

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

[[nodiscard]] constexpr std::string_view to_string(RejectReason reason) noexcept {
  switch (reason) {
    case RejectReason::none: return "none";
#define HSA_REJECT_NAME(reason) \
  case RejectReason::reason: return #reason;
    HSA_REJECT_REASONS(HSA_REJECT_NAME)
#undef HSA_REJECT_NAME
  }
  return "invalid";
}

}  // namespace hsa::daemon
