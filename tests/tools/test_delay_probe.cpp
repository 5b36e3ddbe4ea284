// hsa-simdev's delay probe (tools/hsa_simdev/delay_probe.hpp) in lockstep with a simulated master
// whose delay is known by construction: every time is an integer of nanoseconds the test chooses,
// so the probe must give each delay exactly, not within a tolerance. No clock is read.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <set>
#include <utility>

#include "tools/hsa_simdev/delay_probe.hpp"

namespace hsa::simdev {
namespace {

constexpr std::int64_t ms = 1'000'000;
constexpr double kp = 85.0;  // hsad's example PI gain, m⁻¹
constexpr double ki = 460.0;

// A device ticking every `tick_ns` (its sample carries the probe's offset), polled by a master that
// reads the latest sample every `poll_ns` at phase `read_phase_ns` and writes the PI command
// computed from it `write_after_ns` later. Returns the delays the test expects, computed from the
// schedule alone: the first read at or after an edge's tick, plus write_after_ns, minus that tick.
struct Lockstep {
  std::int64_t tick_ns = 1 * ms;
  std::int64_t poll_ns = 2 * ms;
  std::int64_t read_phase_ns = 300'000;
  std::int64_t write_after_ns = 1'700'000;
  double rod_m = 0.15;  // the real rod, still: the square wave is all the loop sees move
  bool drop_reactions = false;  // the master writes a constant, whatever it reads

  std::vector<std::int64_t> run(DelayProbe& probe, std::int64_t until_ns) const {
    std::vector<std::int64_t> expected;
    double served = rod_m;
    double integral = 0.0;
    std::deque<std::pair<std::int64_t, double>> pending;  // (write time, command)
    std::int64_t next_tick = 0, next_read = read_phase_ns;
    std::int64_t last_edge_tick = -1;
    double last_offset = std::nan("");
    bool edge_unread = false;
    for (std::int64_t t = 0; t < until_ns; t += 1000) {  // 1 µs steps: every event falls on one
      if (t == next_tick) {
        const double offset = probe.offset_at_tick(t);
        if (!std::isnan(last_offset) && offset != last_offset) {
          last_edge_tick = t;
          edge_unread = true;
        }
        last_offset = offset;
        served = rod_m + offset;
        next_tick += tick_ns;
      }
      if (t == next_read) {
        const double e = rod_m - served;  // setpoint at the rod: e is minus the offset
        integral += ki * e * 1e-3;        // the integral's drift between writes
        double u = kp * e + integral + 1e-3;  // + a static opening: never 0 once running
        if (drop_reactions) u = 1e-3;  // a loop that is not closed: a constant opening
        pending.emplace_back(t + write_after_ns, u);
        if (edge_unread && !drop_reactions) expected.push_back(t + write_after_ns - last_edge_tick);
        edge_unread = false;
        next_read += poll_ns;
      }
      while (!pending.empty() && pending.front().first == t) {
        probe.on_command(pending.front().second, t);
        pending.pop_front();
      }
    }
    return expected;
  }
};

DelayProbeSettings settings(std::int64_t jitter_ns) {
  DelayProbeSettings s;
  s.step_m = 0.002;  // Kp·step = 0.17 of an opening per edge
  s.hold_ns = 20 * ms;
  s.jitter_ns = jitter_ns;
  s.threshold = 0.05;
  return s;
}

TEST(DelayProbe, GivesEachDelayOfALockstepMasterExactly) {
  DelayProbe probe(settings(3 * ms));
  const Lockstep master;
  const std::vector<std::int64_t> expected = master.run(probe, 3000 * ms);
  ASSERT_GE(expected.size(), 100u);
  // The last edge may still wait for its write when the run ends.
  ASSERT_GE(probe.delays_ns().size() + 1, expected.size());
  ASSERT_LE(probe.delays_ns().size(), expected.size());
  for (std::size_t i = 0; i < probe.delays_ns().size(); ++i) EXPECT_EQ(probe.delays_ns()[i], expected[i]) << i;
  EXPECT_EQ(probe.misses(), 0u);
  // The jitter puts edges at different phases of the 2 ms poll: the delays are not all one value.
  const std::set<std::int64_t> distinct(probe.delays_ns().begin(), probe.delays_ns().end());
  EXPECT_GE(distinct.size(), 2u);
  for (const std::int64_t d : probe.delays_ns()) {
    EXPECT_GE(d, master.write_after_ns);
    EXPECT_LE(d, master.write_after_ns + master.poll_ns);
  }
}

TEST(DelayProbe, WithoutJitterEveryEdgeFallsOnTheSamePhase) {
  // hold = 20 ms, a multiple of both the tick and the poll: every edge is at the same phase, so
  // every delay is the same, known value. The first nonzero command is written at 2 ms (read at
  // 0.3, written 1.7 ms later), so the probe starts at the 3 ms tick and its edges fall at 23,
  // 43, ... ms: read at the next 2k + 0.3 ms, 1.3 ms later, and written 1.7 ms after that.
  DelayProbe probe(settings(0));
  const Lockstep master;
  const std::vector<std::int64_t> expected = master.run(probe, 1000 * ms);
  ASSERT_GE(probe.delays_ns().size(), 40u);
  for (const std::int64_t d : probe.delays_ns()) EXPECT_EQ(d, 3 * ms);
  EXPECT_EQ(probe.misses(), 0u);
  EXPECT_GE(expected.size(), probe.delays_ns().size());
}

TEST(DelayProbe, AMasterThatNeverReactsGivesMissesNotDelays) {
  DelayProbe probe(settings(3 * ms));
  Lockstep master;
  master.drop_reactions = true;
  master.run(probe, 1000 * ms);
  EXPECT_TRUE(probe.delays_ns().empty());
  EXPECT_GE(probe.misses(), 30u);
  EXPECT_EQ(probe.misses() + 1, probe.edges());  // every edge but the one still waiting
}

TEST(DelayProbe, StartsOnlyOnceTheLoopWritesANonzeroCommand) {
  DelayProbe probe(settings(0));
  // The safe value, 0, while the axis is disabled: no edge, so no miss either.
  for (std::int64_t t = 0; t < 500 * ms; t += ms) {
    EXPECT_EQ(probe.offset_at_tick(t), -0.001);
    probe.on_command(0.0, t);
  }
  EXPECT_EQ(probe.edges(), 0u);
  EXPECT_EQ(probe.misses(), 0u);
}

TEST(DelayProbe, AChangeAgainstTheEdgeOrBelowTheThresholdIsNoReaction) {
  DelayProbeSettings s = settings(0);
  DelayProbe probe(s);
  probe.on_command(0.1, 0);
  probe.offset_at_tick(0);             // starts: the first edge is due at 20 ms
  EXPECT_EQ(probe.offset_at_tick(20 * ms), 0.001);  // an edge up: the command must fall
  probe.on_command(0.1 + 0.2, 21 * ms);   // the wrong way
  probe.on_command(0.3 - 0.049, 22 * ms);  // the right way, under the threshold
  EXPECT_TRUE(probe.delays_ns().empty());
  probe.on_command(0.251 - 0.06, 23 * ms);  // over the threshold: the reaction
  ASSERT_EQ(probe.delays_ns().size(), 1u);
  EXPECT_EQ(probe.delays_ns()[0], 3 * ms);
  probe.on_command(0.191 - 0.2, 24 * ms);  // a second fall: the edge has had its reaction
  EXPECT_EQ(probe.delays_ns().size(), 1u);
}

TEST(DelayProbe, ACommandTakenBeforeTheEdgeOrToOrFromTheSafeValueIsNoReaction) {
  DelayProbe probe(settings(0));
  probe.on_command(0.1, 0);
  probe.offset_at_tick(0);
  ASSERT_EQ(probe.offset_at_tick(20 * ms), 0.001);  // an edge up at 20 ms
  probe.on_command(0.0, 21 * ms);     // the axis faulted: the safe value, a fall of 0.1
  probe.on_command(-0.2, 22 * ms);    // enabled again: a fall from the safe value
  EXPECT_TRUE(probe.delays_ns().empty());
  probe.on_command(-0.4, 23 * ms);    // the reaction
  ASSERT_EQ(probe.delays_ns().size(), 1u);
  EXPECT_EQ(probe.delays_ns()[0], 3 * ms);

  ASSERT_EQ(probe.offset_at_tick(40 * ms), -0.001);  // an edge down at 40 ms: the command must rise
  probe.on_command(-0.1, 40 * ms - 1000);  // stamped 1 µs before the edge: an older sample's
  EXPECT_EQ(probe.delays_ns().size(), 1u);
  probe.on_command(0.1, 41 * ms);
  ASSERT_EQ(probe.delays_ns().size(), 2u);
  EXPECT_EQ(probe.delays_ns()[1], 1 * ms);
  EXPECT_EQ(probe.misses(), 0u);
}

}  // namespace
}  // namespace hsa::simdev
