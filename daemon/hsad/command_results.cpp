#include "daemon/hsad/command_results.hpp"

#include <cstdio>
#include <cstring>
#include <utility>

namespace hsa::daemon {

CommandResults::Sender CommandResults::sender_of(const CommandMsg& c) {
  return {std::string(c.operator_id, ::strnlen(c.operator_id, sizeof c.operator_id)), c.counter};
}

std::uint64_t CommandResults::issue(Sender sender) {
  const std::uint64_t id = next_ticket_++;
  tickets_[id % kInFlight] = {id, std::move(sender)};
  return id;
}

bool CommandResults::is_new(const CommandOutcome& outcome) const {
  return outcome.ticket != 0 && outcome.ticket > answered_;
}

void CommandResults::answer(const CommandOutcome& outcome, const std::string& reason) {
  if (!is_new(outcome)) return;
  answered_ = outcome.ticket;
  const Ticket& t = tickets_[outcome.ticket % kInFlight];
  if (t.id != outcome.ticket) return;  // forgotten: too many in flight
  decide(t.sender, outcome.accepted, outcome.accepted ? std::string() : reason);
}

void CommandResults::decide(Sender sender, bool accepted, std::string reason) {
  last_ = {std::move(sender), accepted, std::move(reason)};
}

void CommandResults::fill(StatusSample& s) const {
  std::snprintf(s.result_operator, sizeof s.result_operator, "%s", last_.sender.operator_id.c_str());
  s.result_counter = last_.sender.counter;
  s.result_accepted = last_.accepted;
  std::snprintf(s.result_reason, sizeof s.result_reason, "%s", last_.reason.c_str());
}

}  // namespace hsa::daemon
