// TimelineOffset: CLOCK_MONOTONIC placed on the daemon's timeline from the reads' own
// measurements, unmoved by a read the host held up.
#include "drivers/timeline_offset.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace hsa::io {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kEpoch = 5'000 * kMs;  // CLOCK_MONOTONIC at the daemon's start

// A cycle that started at `t` on the timeline and reached read() `late_ns` after.
std::int64_t read_at(TimelineOffset& o, std::int64_t t, std::int64_t late_ns) {
  return o.measure(Timestamp{t}, kEpoch + t + late_ns);
}

TEST(TimelineOffset, TheQuickestReadGivesTheOffset) {
  TimelineOffset o;
  read_at(o, 1 * kMs, 7'000);
  read_at(o, 2 * kMs, 2'000);
  EXPECT_EQ(read_at(o, 3 * kMs, 9'000), -kEpoch - 2'000);
  EXPECT_EQ(o.on_timeline(kEpoch + 2 * kMs + 500'000), Timestamp{2 * kMs + 500'000 - 2'000});
}

// The failure it exists for: samples polled every 2 ms while the rod moves; the cycle at 10 ms is
// held up 40 ms before its read, and the newest sample then was polled at 49 ms. Stamped by its
// age at that read (t - age) it would sit at 9 ms, 1 ms after the sample before it (polled at
// 8 ms): 41 ms of travel put into 1 ms.
TEST(TimelineOffset, AHeldUpReadStampsASampleWhenItWasPolled) {
  TimelineOffset o;
  for (std::int64_t t = 0; t <= 9 * kMs; t += kMs) read_at(o, t, 3'000);
  const Timestamp before = o.on_timeline(kEpoch + 8 * kMs);

  const std::int64_t t = 10 * kMs;
  const std::int64_t now = kEpoch + t + 40 * kMs;
  o.measure(Timestamp{t}, now);
  const std::int64_t polled = kEpoch + 49 * kMs;
  const Timestamp held = o.on_timeline(polled);
  EXPECT_EQ((held - before).count(), 41 * kMs);
  // The old stamp, t - age, against the same earlier sample (placed 3 µs early by the steady reads):
  EXPECT_EQ((Timestamp{t} - Timestamp{now - polled} - before).count(), 1 * kMs + 3'000);
}

TEST(TimelineOffset, HeldUpReadsInARowDoNotMoveIt) {
  TimelineOffset o;
  read_at(o, 0, 1'000);
  for (std::int64_t k = 1; k < static_cast<std::int64_t>(TimelineOffset::kWindow); ++k) {
    EXPECT_EQ(read_at(o, k * kMs, 30 * kMs), -kEpoch - 1'000) << "read " << k;
  }
  // After a whole window of held-up reads the estimate is only as good as the best of them:
  // a host that late on every cycle has no better measure to give.
  EXPECT_EQ(read_at(o, 100 * kMs, 30 * kMs), -kEpoch - 30 * kMs);
}

// A caller whose `t` runs at another rate than CLOCK_MONOTONIC (a test stepping it by hand) is
// followed: the estimate is never older than the window.
TEST(TimelineOffset, FollowsATimelineThatDriftsWithinOneWindow) {
  TimelineOffset o;
  std::int64_t estimate = 0;
  // t advances 1 ms per read, CLOCK_MONOTONIC 1.1 ms: the true offset falls 0.1 ms per read.
  for (std::int64_t k = 0; k < 100; ++k) estimate = o.measure(Timestamp{k * kMs}, kEpoch + k * 1'100'000);
  const std::int64_t last = 99 * kMs - (kEpoch + 99 * 1'100'000);
  EXPECT_EQ(estimate - last, static_cast<std::int64_t>(TimelineOffset::kWindow - 1) * 100'000);
}

}  // namespace
}  // namespace hsa::io
