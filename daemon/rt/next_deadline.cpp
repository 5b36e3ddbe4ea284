#include "daemon/rt/next_deadline.hpp"

namespace hsa::daemon {

NextDeadline next_deadline(std::int64_t now_ns, std::int64_t scheduled_ns,
                           std::int64_t period_ns) noexcept {
  const std::int64_t on_time = scheduled_ns + period_ns;
  if (now_ns <= on_time) {
    return {on_time, 0};
  }
  // Periods elapsed since scheduled_ns, rounded up: the first grid point at or after now_ns is
  // scheduled_ns + elapsed · period_ns, and the ones strictly between are skipped.
  const std::int64_t since = now_ns - scheduled_ns;
  const std::int64_t elapsed = (since + period_ns - 1) / period_ns;
  return {scheduled_ns + elapsed * period_ns, static_cast<std::uint64_t>(elapsed - 1)};
}

}  // namespace hsa::daemon
