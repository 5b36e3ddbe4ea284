// The answer to each operator's command, matched to its sender for the axis's status.
//
// A command reaches the RT thread without its sender's name (the ring carries the supervisor's
// AxisCommand): the operator thread gives it a ticket and remembers whose it was, and when the
// axis answers that ticket (a CommandOutcome from the port's answer ring, one per command), the
// outcome becomes the sender's result. Commands the operator thread decides itself (GAINS, a
// RESET refused before it reaches the axis) get their result here directly. Status carries the
// most recent results (StatusSample::kMaxResults, oldest first), so every command is answered
// however many arrive between two status messages; hsactl waits for its own counter there, so a
// refusal is printed with its reason at once instead of looking like a timeout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>

#include "daemon/axis/port_messages.hpp"
#include "daemon/supervisor/command.hpp"

namespace hsa::daemon {

class CommandResults {
 public:
  struct Result {
    std::string operator_id;
    std::int64_t counter = 0;
    bool accepted = false;
    std::string reason;  // empty when accepted
  };

  // A ticket for a command of `sender` that goes to the RT thread.
  std::uint64_t issue(const CommandSender& sender);
  // Takes the axis's outcome of a ticket issued here as its sender's result; `reason` words a
  // refusal. An outcome without a ticket (the daemon's own commands), one answered already, or one
  // forgotten among too many in flight answers nobody.
  void answer(const CommandOutcome& outcome, const std::string& reason);
  // A command decided on the operator thread.
  void decide(const CommandSender& sender, bool accepted, const std::string& reason);

  // The most recent results, oldest first (at most StatusSample::kMaxResults).
  [[nodiscard]] const std::deque<Result>& recent() const { return recent_; }
  void fill(StatusSample& s) const;

 private:
  // Commands in flight at once: as many as the port's command ring holds.
  static constexpr std::size_t kInFlight = 64;
  struct Ticket {
    std::uint64_t id = 0;
    CommandSender sender;
  };
  Ticket tickets_[kInFlight];
  std::uint64_t next_ticket_ = 1;
  std::deque<Result> recent_;
};

}  // namespace hsa::daemon
