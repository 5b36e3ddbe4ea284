// The axis's answer to a command reaches the operator who sent it, once, and only for tickets the
// operator thread issued; the daemon's own commands answer nobody; status carries the most recent
// answers, so none is lost to the next.
#include "daemon/hsad/command_results.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

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

CommandSender sender(const char* id, std::int64_t counter) {
  CommandSender s;
  std::strncpy(s.operator_id, id, sizeof s.operator_id - 1);
  s.counter = counter;
  return s;
}

TEST(CommandResults, TheAxisAnswerGoesToTheSenderOfItsTicket) {
  CommandResults r;
  const std::uint64_t alice = r.issue(sender("alice", 41));
  const std::uint64_t bob = r.issue(sender("bob", 7));
  EXPECT_NE(alice, bob);

  r.answer(outcome(alice, false, Refusal::reset_first), "axis in FAULT: reset first");
  ASSERT_EQ(r.recent().size(), 1u);
  EXPECT_EQ(r.recent().back().operator_id, "alice");
  EXPECT_EQ(r.recent().back().counter, 41);
  EXPECT_FALSE(r.recent().back().accepted);
  EXPECT_EQ(r.recent().back().reason, "axis in FAULT: reset first");

  r.answer(outcome(bob, true), "ignored: accepted");
  ASSERT_EQ(r.recent().size(), 2u);
  EXPECT_EQ(r.recent().back().operator_id, "bob");
  EXPECT_TRUE(r.recent().back().accepted);
  EXPECT_EQ(r.recent().back().reason, "");

  StatusSample s;
  r.fill(s);
  ASSERT_EQ(s.num_results, 2u);
  EXPECT_STREQ(s.results[0].from.operator_id, "alice");
  EXPECT_EQ(s.results[0].from.counter, 41);
  EXPECT_FALSE(s.results[0].accepted);
  EXPECT_STREQ(s.results[0].reason, "axis in FAULT: reset first");
  EXPECT_STREQ(s.results[1].from.operator_id, "bob");
  EXPECT_EQ(s.results[1].from.counter, 7);
  EXPECT_TRUE(s.results[1].accepted);
  EXPECT_STREQ(s.results[1].reason, "");
}

TEST(CommandResults, AnOutcomeIsTakenOnceAndTheDaemonsOwnCommandsAnswerNobody) {
  CommandResults r;
  const std::uint64_t t = r.issue(sender("alice", 1));
  r.answer(outcome(t, true), "");
  r.answer(outcome(t, true), "");  // the same outcome again
  r.answer(outcome(0, true), "");  // ticket 0: a disable hsad sent itself
  ASSERT_EQ(r.recent().size(), 1u);
  EXPECT_EQ(r.recent().back().operator_id, "alice");
}

TEST(CommandResults, ATicketForgottenAmongTooManyInFlightAnswersNobody) {
  CommandResults r;
  const std::uint64_t first = r.issue(sender("alice", 1));
  for (int i = 0; i < 64; ++i) (void)r.issue(sender("flood", i));  // overwrites the first's slot
  r.decide(sender("before", 0), true, "");
  r.answer(outcome(first, false, Refusal::reset_first), "axis in FAULT: reset first");
  ASSERT_EQ(r.recent().size(), 1u);
  EXPECT_EQ(r.recent().back().operator_id, "before");  // not given to the flood's sender
}

TEST(CommandResults, StatusKeepsTheMostRecentAnswersOldestFirst) {
  CommandResults r;
  for (std::int64_t counter = 1; counter <= 20; ++counter) r.decide(sender("alice", counter), true, "");
  StatusSample s;
  r.fill(s);
  ASSERT_EQ(s.num_results, StatusSample::kMaxResults);
  EXPECT_EQ(s.results[0].from.counter, 20 - static_cast<std::int64_t>(StatusSample::kMaxResults) + 1);
  EXPECT_EQ(s.results[StatusSample::kMaxResults - 1].from.counter, 20);
}

}  // namespace
}  // namespace hsa::daemon
