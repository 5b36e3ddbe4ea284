// One commander at a time: the lease an operator holds on an axis (LCM thread only).
//
// An operator takes the axis with ACQUIRE and from then on only that operator's setpoints and
// commands reach it; every accepted message of the holder renews the lease. It ends with RELEASE,
// when `timeout` passes without a message from the holder, or when another operator takes it
// with ACQUIRE and `force` (which hsad logs). While nobody holds the axis, every authenticated
// operator may command it, as before leases existed. DISABLE is obeyed from every authenticated
// operator, holder or not: stopping an axis must never wait for permission.
//
// The operator ids are the authenticated ones (message_authenticator.hpp), so without
// authentication (require_auth = false) the lease is only as good as what senders claim.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

namespace hsa::daemon {

class CommandLease {
 public:
  using Clock = std::chrono::steady_clock;

  enum class Request {
    motion,         // a setpoint, or ENABLE, RESET, MODE, GAINS
    disable,        // DISABLE: always obeyed
    acquire,        // ACQUIRE
    acquire_force,  // ACQUIRE with force: taken from its holder
    release,        // RELEASE
  };

  enum class Outcome {
    granted,       // go ahead (the holder's lease is renewed)
    taken_over,    // acquire_force took the lease from another holder: previous_holder() says who
    held_by_other  // refused: holder() is someone else
  };

  explicit CommandLease(Clock::duration timeout) : timeout_(timeout) {}

  // Decides on `operator_id`'s request at `now`, and updates the lease.
  Outcome request(std::string_view operator_id, Request request, Clock::time_point now);

  // The operator holding the axis at `now` ("" when nobody does or the lease ran out).
  [[nodiscard]] const std::string& holder(Clock::time_point now);
  // Time left on the lease at `now` (zero when nobody holds it).
  [[nodiscard]] Clock::duration remaining(Clock::time_point now);
  // Who held the lease before the last taken_over.
  [[nodiscard]] const std::string& previous_holder() const { return previous_; }

 private:
  void expire(Clock::time_point now);

  Clock::duration timeout_;
  std::string holder_;
  std::string previous_;
  Clock::time_point expires_{};
};

}  // namespace hsa::daemon
