// TickDecimator: which RT cycles publish an axis's telemetry.
#include <cstdint>
#include <stdexcept>

#include <gtest/gtest.h>

#include "daemon/axis/tick_decimator.hpp"

namespace hsa::daemon {
namespace {

TEST(TickDecimator, TakesTheFirstCycleOfEachWindow) {
  EXPECT_THROW(TickDecimator(0), std::invalid_argument);
  TickDecimator d(10);
  int taken = 0;
  for (std::uint64_t tick = 0; tick < 1000; ++tick) taken += d.take(tick) ? 1 : 0;
  EXPECT_EQ(taken, 100);

  TickDecimator e(10);
  EXPECT_TRUE(e.take(5));
  EXPECT_FALSE(e.take(9));
  EXPECT_TRUE(e.take(13));  // an overrun skipped tick 10: the next cycle of its window stands in
  EXPECT_FALSE(e.take(19));
  EXPECT_TRUE(e.take(40));  // windows a stall skipped whole stay empty
}

}  // namespace
}  // namespace hsa::daemon
