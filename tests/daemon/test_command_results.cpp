// The axis's answer to a command reaches the operator who sent it, once, and only for tickets the
// operator thread issued; the daemon's own commands answer nobody.
#include "daemon/hsad/command_results.hpp"

#include <gtest/gtest.h>

#include <cstring>

namespace hsa::daemon {
namespace {

CommandOutcome outcome(std::uint64_t ticket, bool accepted, Refusal refusal = Refusal::none) {
  CommandOutcome o;
  o.seq = ticket + 100;  // the RT side's own numbering, unrelated to tickets
  o.ticket = ticket;
  o.kind = CommandKind::enable;
  o.accepted = accepted;
  o.refusal = refusal;
  return o;
}

TEST(CommandResults, TheAxisAnswerGoesToTheSenderOfItsTicket) {
  CommandResults r;
  const std::uint64_t alice = r.issue({"alice", 41});
  const std::uint64_t bob = r.issue({"bob", 7});
  EXPECT_NE(alice, bob);

  ASSERT_TRUE(r.is_new(outcome(alice, false, Refusal::reset_first)));
  r.answer(outcome(alice, false, Refusal::reset_first), "axis in FAULT: reset first");
  EXPECT_EQ(r.last().sender.operator_id, "alice");
  EXPECT_EQ(r.last().sender.counter, 41);
  EXPECT_FALSE(r.last().accepted);
  EXPECT_EQ(r.last().reason, "axis in FAULT: reset first");

  r.answer(outcome(bob, true), "ignored: accepted");
  EXPECT_EQ(r.last().sender.operator_id, "bob");
  EXPECT_TRUE(r.last().accepted);
  EXPECT_EQ(r.last().reason, "");

  StatusSample s;
  r.fill(s);
  EXPECT_STREQ(s.result_operator, "bob");
  EXPECT_EQ(s.result_counter, 7);
  EXPECT_TRUE(s.result_accepted);
  EXPECT_STREQ(s.result_reason, "");
}

TEST(CommandResults, AnOutcomeIsTakenOnceAndTheDaemonsOwnCommandsAnswerNobody) {
  CommandResults r;
  const std::uint64_t t = r.issue({"alice", 1});
  r.answer(outcome(t, true), "");
  EXPECT_FALSE(r.is_new(outcome(t, true)));  // the same telemetry, polled again
  r.decide({"carol", 3}, false, "gains over max_kp");
  r.answer(outcome(t, true), "");             // still the old outcome: carol's result stays
  EXPECT_EQ(r.last().sender.operator_id, "carol");
  EXPECT_FALSE(r.is_new(outcome(0, true)));   // ticket 0: a disable hsad sent itself
}

TEST(CommandResults, ATicketForgottenAmongTooManyInFlightAnswersNobody) {
  CommandResults r;
  const std::uint64_t first = r.issue({"alice", 1});
  for (int i = 0; i < 16; ++i) (void)r.issue({"flood", i});  // overwrites the first's slot
  r.decide({"before", 0}, true, "");
  r.answer(outcome(first, false, Refusal::reset_first), "axis in FAULT: reset first");
  EXPECT_EQ(r.last().sender.operator_id, "before");  // not given to the flood's sender
}

}  // namespace
}  // namespace hsa::daemon
