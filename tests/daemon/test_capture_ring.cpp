// The flight recorder's ring (daemon/recorder/capture_ring.hpp): wrap-around, the window around a
// trigger, overlapping triggers counted, no allocation on the RT side, and no torn or missing row
// when the RT side and the writer run on two threads at once.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "daemon/recorder/capture_ring.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::daemon {
namespace {

// A row whose every field is derived from its tick: a torn row (half of one tick, half of
// another) fails consistent().
void fill(RecorderRow& r, std::uint64_t tick) {
  r.tick = tick;
  r.t_ns = static_cast<std::int64_t>(tick) * 100'000;
  const double x = static_cast<double>(tick);
  r.setpoint = x;
  r.rod_setpoint_m = x + 1;
  r.position_m = x + 2;
  r.velocity_m_s = x + 3;
  r.following_error_m = x + 4;
  r.opening = x + 5;
  r.command = x + 6;
  r.spool_m = x + 7;
  r.pressure_a_pa = x + 8;
  r.pressure_b_pa = x + 9;
  r.integral = x + 10;
  r.active_faults = static_cast<std::uint32_t>(tick);
  r.lateness_ns = static_cast<std::int32_t>(tick % 1000);
  r.exec_ns = static_cast<std::int32_t>(tick % 777);
}

bool consistent(const RecorderRow& r) {
  const double x = static_cast<double>(r.tick);
  return r.t_ns == static_cast<std::int64_t>(r.tick) * 100'000 && r.setpoint == x && r.rod_setpoint_m == x + 1 &&
         r.position_m == x + 2 && r.velocity_m_s == x + 3 && r.following_error_m == x + 4 && r.opening == x + 5 &&
         r.command == x + 6 && r.spool_m == x + 7 && r.pressure_a_pa == x + 8 && r.pressure_b_pa == x + 9 &&
         r.integral == x + 10 && r.active_faults == static_cast<std::uint32_t>(r.tick) &&
         r.lateness_ns == static_cast<std::int32_t>(r.tick % 1000) && r.exec_ns == static_cast<std::int32_t>(r.tick % 777);
}

// The RT side's part of one cycle.
void cycle(CaptureRing& ring, std::uint64_t tick, bool trigger = false) {
  fill(ring.slot(), tick);
  if (trigger) ring.trigger({.tick = tick, .t_ns = static_cast<std::int64_t>(tick) * 100'000});
  ring.commit();
}

TEST(CaptureRing, RefusesAWindowThatDoesNotFit) {
  EXPECT_THROW(CaptureRing(1, 0), std::invalid_argument);
  EXPECT_THROW(CaptureRing(10, 10), std::invalid_argument);
  EXPECT_NO_THROW(CaptureRing(10, 9));
}

TEST(CaptureRing, NothingIsHandedOverWithoutATrigger) {
  CaptureRing ring(100, 20);
  for (std::uint64_t t = 0; t < 1000; ++t) cycle(ring, t);
  EXPECT_EQ(ring.take(), nullptr);
  EXPECT_EQ(ring.counts().triggers, 0u);
}

TEST(CaptureRing, AfterWrapTheWindowIsTheLastRowsWithThePostTriggerRowsAfterTheTrigger) {
  CaptureRing ring(100, 20);
  std::uint64_t t = 0;
  for (; t < 537; ++t) cycle(ring, t);  // wrapped five times
  const std::uint64_t trigger_tick = t;
  cycle(ring, t++, true);
  for (int i = 0; i < 19; ++i) {
    cycle(ring, t++);
    ASSERT_EQ(ring.take(), nullptr) << "frozen before its post-trigger rows, at " << i;
  }
  cycle(ring, t++);  // the 20th row after the trigger
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->size(), 100u);
  EXPECT_EQ(c->trigger_offset(), 79u);  // 79 rows before it, itself, 20 after
  EXPECT_EQ(c->row(c->trigger_offset()).tick, trigger_tick);
  EXPECT_EQ(c->why.tick, trigger_tick);
  for (std::size_t k = 0; k < c->size(); ++k) {
    ASSERT_EQ(c->row(k).tick, trigger_tick - 79 + k) << k;  // oldest first, no gap
    ASSERT_TRUE(consistent(c->row(k))) << k;
  }
  EXPECT_EQ(ring.counts().frozen, 1u);
}

TEST(CaptureRing, ATriggerBeforeTheRingFilledHasTheRowsThereAre) {
  CaptureRing ring(100, 10);
  std::uint64_t t = 0;
  for (; t < 30; ++t) cycle(ring, t);
  cycle(ring, t++, true);
  for (int i = 0; i < 10; ++i) cycle(ring, t++);
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->size(), 41u);
  EXPECT_EQ(c->trigger_offset(), 30u);
  EXPECT_EQ(c->row(0).tick, 0u);
}

TEST(CaptureRing, RecordingGoesOnIntoTheOtherBufferWhileTheWriterHoldsACapture) {
  CaptureRing ring(50, 10);
  std::uint64_t t = 0;
  for (; t < 60; ++t) cycle(ring, t);
  cycle(ring, t++, true);
  for (int i = 0; i < 10; ++i) cycle(ring, t++);
  const Capture* first = ring.take();
  ASSERT_NE(first, nullptr);
  const std::uint64_t last_of_first = first->row(first->size() - 1).tick;
  for (int i = 0; i < 200; ++i) cycle(ring, t++);  // the writer is still reading it
  EXPECT_EQ(first->row(first->size() - 1).tick, last_of_first) << "the RT side wrote into the held buffer";
  for (std::size_t k = 0; k < first->size(); ++k) ASSERT_TRUE(consistent(first->row(k)));
  ring.release();
  EXPECT_EQ(ring.take(), nullptr);
}

TEST(CaptureRing, ATriggerDuringThePostTriggerRowsIsMergedAndCounted) {
  CaptureRing ring(100, 20);
  std::uint64_t t = 0;
  for (; t < 200; ++t) cycle(ring, t);
  const std::uint64_t first_trigger = t;
  cycle(ring, t++, true);
  for (int i = 0; i < 5; ++i) cycle(ring, t++);
  cycle(ring, t++, true);  // a second fault 6 rows later
  for (int i = 0; i < 14; ++i) cycle(ring, t++);
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.tick, first_trigger);  // the window is the first trigger's
  EXPECT_EQ(c->row(c->trigger_offset()).tick, first_trigger);
  EXPECT_EQ(c->merged, 1u);
  const CaptureRingCounts n = ring.counts();
  EXPECT_EQ(n.triggers, 2u);
  EXPECT_EQ(n.merged, 1u);
  EXPECT_EQ(n.frozen, 1u);
}

TEST(CaptureRing, ACaptureWaitsForTheWriterAndIsDroppedAndCountedOnlyOnceItsTriggerRowIsGone) {
  CaptureRing ring(100, 10);
  std::uint64_t t = 0;
  cycle(ring, t++, true);
  for (int i = 0; i < 10; ++i) cycle(ring, t++);
  ASSERT_NE(ring.take(), nullptr);  // the writer holds the first capture...

  const std::uint64_t second = t;
  cycle(ring, t++, true);  // ...when the second fault comes
  for (int i = 0; i < 30; ++i) cycle(ring, t++);  // its post-trigger rows are in; the writer is slow
  EXPECT_EQ(ring.counts().frozen, 1u);
  ring.release();
  cycle(ring, t++);  // frozen at the next row, with more post-trigger rows than asked for
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.tick, second);
  EXPECT_EQ(c->row(c->trigger_offset()).tick, second);
  EXPECT_EQ(c->size() - c->trigger_offset() - 1, 31u);

  // A third capture with the writer holding the second for longer than the ring lasts: dropped.
  cycle(ring, t++, true);
  for (int i = 0; i < 98; ++i) cycle(ring, t++);
  EXPECT_EQ(ring.counts().dropped, 0u);  // the ring still holds the trigger row, 99 rows ago
  cycle(ring, t++);  // the trigger row is the oldest now: the next row would overwrite it
  EXPECT_EQ(ring.counts().dropped, 1u);
  EXPECT_FALSE(ring.armed());
  ring.release();
  for (int i = 0; i < 200; ++i) cycle(ring, t++);
  EXPECT_EQ(ring.take(), nullptr);  // the dropped one is not handed over later
  EXPECT_EQ(ring.counts().triggers, 3u);
  EXPECT_EQ(ring.counts().frozen, 2u);
}

// An operator's trigger shapes its own window: fewer rows before, more or fewer after, and the
// ring's own post rows again for the next trigger that asks for none.
TEST(CaptureRing, ATriggersOwnPreAndPostRowsShapeItsWindow) {
  CaptureRing ring(100, 20);
  std::uint64_t t = 0;
  for (; t < 300; ++t) cycle(ring, t);
  const std::uint64_t first = t;
  fill(ring.slot(), t);
  ring.trigger({.kind = TriggerKind::request, .tick = t, .pre_rows = 10, .post_rows = 60});
  ring.commit();
  ++t;
  for (int i = 0; i < 59; ++i) {
    cycle(ring, t++);
    ASSERT_EQ(ring.take(), nullptr) << "frozen before its 60 post-trigger rows, at " << i;
  }
  cycle(ring, t++);
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.kind, TriggerKind::request);
  EXPECT_EQ(c->trigger_offset(), 10u);
  EXPECT_EQ(c->row(0).tick, first - 10);
  EXPECT_EQ(c->size(), 71u);
  ring.release();

  for (int i = 0; i < 150; ++i) cycle(ring, t++);
  cycle(ring, t++, true);  // the ring's own: 20 after, all it holds before
  for (int i = 0; i < 20; ++i) cycle(ring, t++);
  c = ring.take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->size(), 100u);
  EXPECT_EQ(c->trigger_offset(), 79u);
}

TEST(CaptureRing, APostLengthBeyondTheRingIsClampedToIt) {
  CaptureRing ring(50, 5);
  std::uint64_t t = 0;
  fill(ring.slot(), t);
  ring.trigger({.tick = t, .post_rows = 1000});
  ring.commit();
  ++t;
  for (int i = 0; i < 49; ++i) cycle(ring, t++);
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr) << "not frozen once the trigger row and 49 after filled the ring";
  EXPECT_EQ(c->trigger_offset(), 0u);
  EXPECT_EQ(c->size(), 50u);
  EXPECT_EQ(ring.counts().dropped, 0u);
}

TEST(CaptureRing, AManualRequestIsTakenOnce) {
  CaptureRing ring(10, 2);
  EXPECT_FALSE(ring.take_manual_request());
  ring.request_manual();
  EXPECT_TRUE(ring.take_manual_request());
  EXPECT_FALSE(ring.take_manual_request());
}

TEST(CaptureRing, TheRtSideAllocatesNothingOverManyCaptures) {
  CaptureRing ring(1000, 200);
  std::uint64_t t = 0;
  const long before = test::thread_allocations();
  for (int capture = 0; capture < 20; ++capture) {
    for (int i = 0; i < 3000; ++i) cycle(ring, t++, i == 1500);
    if (ring.take() != nullptr) ring.release();
  }
  EXPECT_EQ(test::thread_allocations() - before, 0);
  EXPECT_EQ(ring.counts().frozen, 20u);
}

// The RT side at full speed on one thread, the writer on another taking and releasing captures:
// every row of every capture is whole and the ticks run without a gap.
TEST(CaptureRing, NoRowIsTornOrMissingWithTheWriterOnAnotherThread) {
  CaptureRing ring(2000, 500);
  std::atomic<bool> done{false};
  std::uint64_t checked = 0, bad = 0;
  std::atomic<std::uint64_t> captures{0};
  std::thread writer([&] {
    while (!done.load()) {
      if (const Capture* c = ring.take()) {
        for (std::size_t k = 0; k < c->size(); ++k) {
          const RecorderRow& r = c->row(k);
          if (!consistent(r) || (k > 0 && r.tick != c->row(k - 1).tick + 1)) ++bad;
          ++checked;
        }
        if (c->row(c->trigger_offset()).tick != c->why.tick) ++bad;
        ++captures;
        ring.release();
      }
    }
  });
  // Until the writer has checked 20 captures (the RT side outruns it: many triggers are merged or
  // dropped meanwhile, which is counted below), or 20 s on a machine that starves the writer.
  std::uint64_t t = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (captures.load() < 20 && std::chrono::steady_clock::now() < give_up) {
    for (int i = 0; i < 100'000; ++i, ++t) cycle(ring, t, t % 3001 == 0);
  }
  // Let the writer finish the last one it took.
  while (ring.take() != nullptr) std::this_thread::yield();
  done = true;
  writer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_GE(captures.load(), 20u);
  EXPECT_GT(checked, captures.load() * 500);
  const CaptureRingCounts n = ring.counts();
  EXPECT_EQ(n.frozen, captures.load());
  EXPECT_EQ(n.triggers, n.frozen + n.merged + n.dropped + (ring.armed() ? 1 : 0));  // every trigger accounted for
}

}  // namespace
}  // namespace hsa::daemon
