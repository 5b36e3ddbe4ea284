// The answer to each operator's command, matched to its sender for the axis's status.
//
// A command reaches the RT thread without its sender's name (the ring carries plain numbers): the
// operator thread gives it a ticket, remembers whose it was, and when the axis's telemetry reports
// the outcome of that ticket (AxisSupervisor::last_command), the outcome becomes the sender's
// result in status (result_operator, result_counter, result_accepted, result_reason). Commands the
// operator thread decides itself (GAINS, a RESET refused before it reaches the axis) get their
// result here directly. hsactl waits for its own counter in that result, so a refusal is printed
// with its reason at once instead of looking like a timeout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/lcm_bridge/rt_messages.hpp"
#include "daemon/supervisor/command.hpp"

namespace hsa::daemon {

class CommandResults {
 public:
  // The sender of a command, as the LCM side handed it over.
  struct Sender {
    std::string operator_id;
    std::int64_t counter = 0;
  };
  struct Result {
    Sender sender;
    bool accepted = false;
    std::string reason;  // empty when accepted
  };

  static Sender sender_of(const CommandMsg& c);

  // A ticket for a command of `sender` that goes to the RT thread.
  std::uint64_t issue(Sender sender);
  // Whether `outcome` answers a ticket issued here and not yet answered (the daemon's own commands
  // carry none).
  [[nodiscard]] bool is_new(const CommandOutcome& outcome) const;
  // Takes the axis's outcome of a ticket as its sender's result; `reason` words a refusal.
  void answer(const CommandOutcome& outcome, const std::string& reason);
  // A command decided on the operator thread.
  void decide(Sender sender, bool accepted, std::string reason);

  [[nodiscard]] const Result& last() const { return last_; }
  void fill(StatusSample& s) const;

 private:
  // Commands in flight at once: an axis answers within a cycle, the operator thread polls at
  // ~100 Hz, so more than a few means senders far faster than anyone types; the oldest is forgotten.
  static constexpr std::size_t kInFlight = 16;
  struct Ticket {
    std::uint64_t id = 0;
    Sender sender;
  };
  Ticket tickets_[kInFlight];
  std::uint64_t next_ticket_ = 1;
  std::uint64_t answered_ = 0;  // the last ticket whose outcome was taken
  Result last_;
};

}  // namespace hsa::daemon
