// The gpiod plugin's charge pump (drivers/gpiod/charge_pump.hpp), with no GPIO: the level it
// drives on each write() cycle, for several divisors and both safe levels, and that stopping it
// returns it to the safe level and restarts its wave.
#include <gtest/gtest.h>

#include <string>

#include "drivers/gpiod/charge_pump.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io::gpiod {
namespace {

// The levels of `steps` write() cycles, as "0101...".
std::string wave(ChargePump& pump, int steps) {
  std::string levels;
  for (int i = 0; i < steps; ++i) levels += pump.step() ? '1' : '0';
  return levels;
}

TEST(GpiodChargePump, DivisorOneTogglesEveryCycleFromTheSafeLevel) {
  ChargePump pump;
  EXPECT_FALSE(pump.level());  // stopped: safe
  EXPECT_EQ(wave(pump, 8), "10101010");
}

TEST(GpiodChargePump, DivisorNTogglesEveryNthCycle) {
  ChargePump two(2);
  EXPECT_EQ(wave(two, 12), "011001100110");
  ChargePump three(3);
  EXPECT_EQ(wave(three, 12), "001110001110");
  // The period is 2 * divisor cycles, with as many cycles high as low.
  for (const std::uint32_t divisor : {1u, 4u, 7u, 50u}) {
    ChargePump pump(divisor);
    int high = 0;
    int edges = 0;
    bool previous = pump.level();
    for (std::uint32_t i = 0; i < 20 * divisor; ++i) {
      const bool level = pump.step();
      high += level ? 1 : 0;
      edges += level != previous ? 1 : 0;
      previous = level;
    }
    EXPECT_EQ(high, static_cast<int>(10 * divisor)) << "divisor " << divisor;
    EXPECT_EQ(edges, 20) << "divisor " << divisor;
  }
}

TEST(GpiodChargePump, ASafeHighPumpStartsHigh) {
  ChargePump pump(2, true);
  EXPECT_TRUE(pump.level());
  EXPECT_EQ(wave(pump, 6), "100110");
  EXPECT_TRUE(pump.stop());
}

TEST(GpiodChargePump, StopHoldsTheSafeLevelAndRestartsTheWave) {
  ChargePump pump(3);
  EXPECT_EQ(wave(pump, 4), "0011");  // stopped mid-wave, high
  EXPECT_FALSE(pump.stop());
  EXPECT_FALSE(pump.level());
  EXPECT_FALSE(pump.stop());  // stays there however often it is stopped
  EXPECT_EQ(wave(pump, 6), "001110");  // the same wave as from the start
}

TEST(GpiodChargePump, AZeroDivisorActsAsOne) {
  ChargePump pump(0);  // the settings refuse 0; the class does not divide by it either
  EXPECT_EQ(pump.divisor(), 1u);
  EXPECT_EQ(wave(pump, 4), "1010");
}

TEST(GpiodChargePump, StepAndStopAllocateNothing) {
  ChargePump pump(5);
  const long before = hsa::test::process_allocations();
  bool sink = false;
  for (int i = 0; i < 10000; ++i) sink ^= pump.step();
  sink ^= pump.stop();
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
  EXPECT_FALSE(pump.level());
  (void)sink;
}

}  // namespace
}  // namespace hsa::io::gpiod
