// The edge latch of the gpiod plugin's e-stop inputs: every change the line makes is reported for
// at least one cycle, including a pulse that starts and ends between two reads, and a steady line
// reads steady.
#include <gtest/gtest.h>

#include "drivers/gpiod/edge_latch.hpp"

namespace hsa::io::gpiod {
namespace {

TEST(EdgeLatch, ASteadyLineReadsItsLevel) {
  EdgeLatch latch;
  latch.reset(true);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(latch.update(true, 0));
  latch.reset(false);
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(latch.update(false, 0));
}

TEST(EdgeLatch, AChangeIsReportedWhenRead) {
  EdgeLatch latch;
  latch.reset(true);
  EXPECT_FALSE(latch.update(false, 1));  // the edge and its new level in one cycle
  EXPECT_FALSE(latch.update(false, 0));
  EXPECT_TRUE(latch.update(true, 1));
  EXPECT_TRUE(latch.update(true, 0));
}

TEST(EdgeLatch, APulseBetweenTwoReadsShowsForOneCycle) {
  EdgeLatch latch;
  latch.reset(true);                     // e-stop loop closed (active low: 1 = not pressed)
  EXPECT_FALSE(latch.update(true, 2));   // pressed and released between the two reads
  EXPECT_TRUE(latch.update(true, 0));    // then the level again
  EXPECT_TRUE(latch.update(true, 0));

  latch.reset(false);                    // and the other way round
  EXPECT_TRUE(latch.update(false, 2));
  EXPECT_FALSE(latch.update(false, 0));
}

TEST(EdgeLatch, APulseWhoseEventsAreCoalescedOrSplitIsStillSeen) {
  EdgeLatch latch;
  latch.reset(true);
  // A controller that merged both edges into one event.
  EXPECT_FALSE(latch.update(true, 1));
  EXPECT_TRUE(latch.update(true, 0));
  // Two pulses in one cycle (four edges): still one cycle of the other value, not a toggle.
  EXPECT_FALSE(latch.update(true, 4));
  EXPECT_TRUE(latch.update(true, 0));
}

TEST(EdgeLatch, AnEdgeDrainedBeforeItsLevelIsReadIsNotAFalsePulse) {
  // The level is read first, then the events: an edge between the two arrives one cycle before
  // its level. It shows the new value at once, and the next read (the new level, no edge)
  // agrees with it.
  EdgeLatch latch;
  latch.reset(false);
  EXPECT_TRUE(latch.update(false, 1));
  EXPECT_TRUE(latch.update(true, 0));
  EXPECT_TRUE(latch.update(true, 0));
}

TEST(EdgeLatch, AChangeAndAPulseBackInOneCycleShowTheNewLevel) {
  EdgeLatch latch;
  latch.reset(false);
  EXPECT_TRUE(latch.update(true, 3));  // 0 -> 1 -> 0 -> 1: the level changed, report it
  EXPECT_TRUE(latch.update(true, 0));
}

}  // namespace
}  // namespace hsa::io::gpiod
