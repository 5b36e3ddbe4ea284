#include "daemon/hsad/command_results.hpp"

#include <cstdio>
#include <cstring>

namespace hsa::daemon {

std::uint64_t CommandResults::issue(const CommandSender& sender) {
  const std::uint64_t id = next_ticket_++;
  tickets_[id % kInFlight] = {id, sender};
  return id;
}

void CommandResults::answer(const CommandOutcome& outcome, const std::string& reason) {
  if (outcome.ticket == 0) return;
  Ticket& t = tickets_[outcome.ticket % kInFlight];
  if (t.id != outcome.ticket) return;  // answered already, or forgotten: too many in flight
  t.id = 0;
  decide(t.sender, outcome.accepted, outcome.accepted ? std::string() : reason);
}

void CommandResults::decide(const CommandSender& sender, bool accepted, const std::string& reason) {
  if (recent_.size() == StatusSample::kMaxResults) recent_.pop_front();
  recent_.push_back({std::string(sender.operator_id, ::strnlen(sender.operator_id, sizeof sender.operator_id)),
                     sender.counter, accepted, reason});
}

void CommandResults::fill(StatusSample& s) const {
  s.num_results = 0;
  for (const Result& r : recent_) {
    CommandResultEntry& e = s.results[s.num_results++];
    std::snprintf(e.from.operator_id, sizeof e.from.operator_id, "%s", r.operator_id.c_str());
    e.from.counter = r.counter;
    e.accepted = r.accepted;
    std::snprintf(e.reason, sizeof e.reason, "%s", r.reason.c_str());
  }
}

}  // namespace hsa::daemon
