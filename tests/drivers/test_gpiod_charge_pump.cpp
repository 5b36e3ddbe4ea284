// The gpiod plugin's charge pump (drivers/gpiod/charge_pump.hpp), with no GPIO: the level it
// drives on each write() cycle, for several divisors and both safe levels; that stopping it, or a
// cycle with its enable off, returns it to the safe level at once and restarts its wave.
#include <gtest/gtest.h>

#include <string>

#include "drivers/gpiod/charge_pump.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io::gpiod {
namespace {

// The levels of `steps` write() cycles with the enable on, as "0101...".
std::string wave(ChargePump& pump, int steps) {
  std::string levels;
  for (int i = 0; i < steps; ++i) levels += pump.step(true) ? '1' : '0';
  return levels;
}

// The levels of write() cycles with the enable of each: "1" on, "0" off.
std::string wave(ChargePump& pump, const std::string& enables) {
  std::string levels;
  for (const char e : enables) levels += pump.step(e == '1') ? '1' : '0';
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
      const bool level = pump.step(true);
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

// LinuxCNC's enable pin: with the enable off the output is the safe level in that very cycle,
// whatever the wave was doing, and it stays there; the wave restarts from the safe level when the
// enable comes back, so its first edge is a divisor later, as after activation.
TEST(GpiodChargePump, AnEnableOffStopsTheWaveInThatCycle) {
  ChargePump one;
  EXPECT_EQ(wave(one, "1111000001111"), "1010000001010");
  EXPECT_EQ(wave(one, "10"), "10");  // high, then off: low in the same cycle
  ChargePump three(3);
  EXPECT_EQ(wave(three, "11110000111111"), "00110000001110");
  ChargePump high(2, true);  // safe high: off holds it high
  EXPECT_EQ(wave(high, "1110001111"), "1001111001");
  EXPECT_TRUE(high.step(false));
  // Off never toggles: a thousand cycles with the enable off, no edge.
  ChargePump pump(1);
  EXPECT_EQ(wave(pump, std::string(1000, '0')), std::string(1000, '0'));
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
  for (int i = 0; i < 10000; ++i) sink ^= pump.step(i % 100 < 90);
  sink ^= pump.stop();
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
  EXPECT_FALSE(pump.level());
  (void)sink;
}

}  // namespace
}  // namespace hsa::io::gpiod
