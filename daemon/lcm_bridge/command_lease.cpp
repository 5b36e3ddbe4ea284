#include "daemon/lcm_bridge/command_lease.hpp"

namespace hsa::daemon {

void CommandLease::expire(Clock::time_point now) {
  if (!holder_.empty() && now >= expires_) holder_.clear();
}

const std::string& CommandLease::holder(Clock::time_point now) {
  expire(now);
  return holder_;
}

CommandLease::Clock::duration CommandLease::remaining(Clock::time_point now) {
  expire(now);
  return holder_.empty() ? Clock::duration::zero() : expires_ - now;
}

CommandLease::Outcome CommandLease::request(std::string_view operator_id, Request request, Clock::time_point now) {
  expire(now);
  const bool mine = !holder_.empty() && holder_ == operator_id;
  const bool others = !holder_.empty() && !mine;
  Outcome outcome = Outcome::granted;
  switch (request) {
    case Request::motion:
      if (others) return Outcome::held_by_other;
      break;
    case Request::disable: break;
    case Request::acquire:
      if (others) return Outcome::held_by_other;
      holder_ = operator_id;
      break;
    case Request::acquire_force:
      if (others) {
        previous_ = holder_;
        outcome = Outcome::taken_over;
      }
      holder_ = operator_id;
      break;
    case Request::release:
      if (others) return Outcome::held_by_other;
      holder_.clear();
      return Outcome::granted;
  }
  if (!holder_.empty() && holder_ == operator_id) expires_ = now + timeout_;
  return outcome;
}

}  // namespace hsa::daemon
