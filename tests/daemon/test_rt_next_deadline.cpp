#include "daemon/rt/next_deadline.hpp"

#include <gtest/gtest.h>

namespace hsa::daemon {
namespace {

constexpr std::int64_t kPeriod = 100'000;     // 100 µs
constexpr std::int64_t kScheduled = 5'000'000'000;

TEST(NextDeadline, OnTimeGoesToTheNextGridPoint) {
  const NextDeadline n = next_deadline(kScheduled + 30'000, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + kPeriod);
  EXPECT_EQ(n.skipped, 0U);
}

TEST(NextDeadline, EndingExactlyOnTheNextDeadlineIsNotAMiss) {
  const NextDeadline n = next_deadline(kScheduled + kPeriod, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + kPeriod);
  EXPECT_EQ(n.skipped, 0U);
}

TEST(NextDeadline, OneNanosecondPastTheNextDeadlineSkipsIt) {
  const NextDeadline n = next_deadline(kScheduled + kPeriod + 1, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + 2 * kPeriod);
  EXPECT_EQ(n.skipped, 1U);
}

TEST(NextDeadline, LateByTwoAndAHalfPeriodsSkipsTwo) {
  const NextDeadline n = next_deadline(kScheduled + 5 * kPeriod / 2, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + 3 * kPeriod);
  EXPECT_EQ(n.skipped, 2U);
}

TEST(NextDeadline, EndingOnALaterGridPointRunsThatOne) {
  const NextDeadline n = next_deadline(kScheduled + 3 * kPeriod, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + 3 * kPeriod);
  EXPECT_EQ(n.skipped, 2U);
}

TEST(NextDeadline, AHundredMillisecondStallSkipsInsteadOfBursting) {
  // Catching up after a 100 ms VM pause would run 1000 late cycles back to back.
  const NextDeadline n = next_deadline(kScheduled + 100'000'000 + 50'000, kScheduled, kPeriod);
  EXPECT_EQ(n.skipped, 1000U);
  EXPECT_EQ(n.next_ns, kScheduled + 1001 * kPeriod);
  EXPECT_GT(n.next_ns, kScheduled + 100'000'000 + 50'000);
}

TEST(NextDeadline, StaysOnTheGrid) {
  for (std::int64_t late = 1; late < 10 * kPeriod; late += 7'919) {
    const NextDeadline n = next_deadline(kScheduled + late, kScheduled, kPeriod);
    EXPECT_EQ((n.next_ns - kScheduled) % kPeriod, 0) << late;
    EXPECT_GE(n.next_ns, kScheduled + late) << late;
    EXPECT_LT(n.next_ns - (kScheduled + late), kPeriod) << late;
    EXPECT_EQ(n.next_ns, kScheduled + static_cast<std::int64_t>(n.skipped + 1) * kPeriod) << late;
  }
}

TEST(NextDeadline, ACycleEndingBeforeItsScheduleStillAdvancesOnePeriod) {
  const NextDeadline n = next_deadline(kScheduled - 10, kScheduled, kPeriod);
  EXPECT_EQ(n.next_ns, kScheduled + kPeriod);
  EXPECT_EQ(n.skipped, 0U);
}

}  // namespace
}  // namespace hsa::daemon
