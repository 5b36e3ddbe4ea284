// One commander at a time (daemon/lcm_bridge/command_lease.hpp): the holder's messages renew the
// lease, others are refused except DISABLE, and the lease ends by release, timeout or force.
#include <gtest/gtest.h>

#include <chrono>

#include "daemon/lcm_bridge/command_lease.hpp"

namespace hsa::daemon {
namespace {

using namespace std::chrono_literals;
using Outcome = CommandLease::Outcome;
using Request = CommandLease::Request;
const CommandLease::Clock::time_point t0{};

TEST(CommandLease, WithoutAHolderEveryOperatorCommands) {
  CommandLease lease(10s);
  EXPECT_EQ(lease.request("alice", Request::motion, t0), Outcome::granted);
  EXPECT_EQ(lease.request("bob", Request::motion, t0), Outcome::granted);
  EXPECT_EQ(lease.holder(t0), "");
  EXPECT_EQ(lease.remaining(t0), 0s);
}

TEST(CommandLease, TheHolderAloneMovesTheAxisButAnyoneDisablesIt) {
  CommandLease lease(10s);
  ASSERT_EQ(lease.request("alice", Request::acquire, t0), Outcome::granted);
  EXPECT_EQ(lease.holder(t0), "alice");
  EXPECT_EQ(lease.request("alice", Request::motion, t0 + 1s), Outcome::granted);
  EXPECT_EQ(lease.request("bob", Request::motion, t0 + 1s), Outcome::held_by_other);
  EXPECT_EQ(lease.request("bob", Request::acquire, t0 + 1s), Outcome::held_by_other);
  EXPECT_EQ(lease.request("bob", Request::release, t0 + 1s), Outcome::held_by_other);
  EXPECT_EQ(lease.request("bob", Request::disable, t0 + 1s), Outcome::granted);
  EXPECT_EQ(lease.holder(t0 + 1s), "alice");  // bob's DISABLE did not take or end the lease
}

TEST(CommandLease, TheHoldersMessagesRenewItAndSilenceEndsIt) {
  CommandLease lease(10s);
  ASSERT_EQ(lease.request("alice", Request::acquire, t0), Outcome::granted);
  EXPECT_EQ(lease.remaining(t0 + 4s), 6s);
  ASSERT_EQ(lease.request("alice", Request::motion, t0 + 8s), Outcome::granted);  // renewed to t0 + 18 s
  EXPECT_EQ(lease.remaining(t0 + 8s), 10s);
  EXPECT_EQ(lease.request("bob", Request::motion, t0 + 17s), Outcome::held_by_other);
  // bob's refused messages do not renew alice's lease.
  EXPECT_EQ(lease.holder(t0 + 18s), "");
  EXPECT_EQ(lease.request("bob", Request::motion, t0 + 18s), Outcome::granted);
  EXPECT_EQ(lease.request("bob", Request::acquire, t0 + 18s), Outcome::granted);
  EXPECT_EQ(lease.holder(t0 + 18s), "bob");
}

TEST(CommandLease, ReleaseFreesTheAxis) {
  CommandLease lease(10s);
  ASSERT_EQ(lease.request("alice", Request::acquire, t0), Outcome::granted);
  EXPECT_EQ(lease.request("alice", Request::release, t0 + 1s), Outcome::granted);
  EXPECT_EQ(lease.holder(t0 + 1s), "");
  EXPECT_EQ(lease.request("bob", Request::motion, t0 + 1s), Outcome::granted);
  // Releasing what nobody holds is harmless.
  EXPECT_EQ(lease.request("bob", Request::release, t0 + 2s), Outcome::granted);
}

TEST(CommandLease, ForceTakesTheLeaseAndNamesThePreviousHolder) {
  CommandLease lease(10s);
  ASSERT_EQ(lease.request("alice", Request::acquire, t0), Outcome::granted);
  EXPECT_EQ(lease.request("bob", Request::acquire_force, t0 + 1s), Outcome::taken_over);
  EXPECT_EQ(lease.previous_holder(), "alice");
  EXPECT_EQ(lease.holder(t0 + 1s), "bob");
  EXPECT_EQ(lease.request("alice", Request::motion, t0 + 1s), Outcome::held_by_other);
  // Forcing a free lease or one's own is a plain acquire.
  EXPECT_EQ(lease.request("bob", Request::acquire_force, t0 + 2s), Outcome::granted);
}

}  // namespace
}  // namespace hsa::daemon
