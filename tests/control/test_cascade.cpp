#include "control/cascade.hpp"

#include <atomic>
#include <cmath>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

// Counts every heap allocation in this test program, so a test can assert that a stretch of
// loop code allocates nothing (docs/architecture.md, real-time rules).
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace hsa::control {
namespace {

constexpr double kExact = 1e-12;

CascadeParams direct_params() {
  CascadeParams p;
  p.drive = ValveDrive::direct;
  return p;
}

CascadeParams proportional_params() {
  CascadeParams p;
  p.valve.bias_current_a = 1.2;
  p.valve.feedforward_a_per_m = 250.0;
  p.valve.proportional_a_per_m = 3300.0;
  return p;
}

TEST(Cascade, DefaultsAreTheDesignRates) {
  const CascadeParams p;
  EXPECT_EQ(p.cylinder.period_s, 1e-3);
  EXPECT_EQ(p.valve.period_s, 1e-4);
  EXPECT_EQ(p.valve_ticks_per_cylinder_tick, 10u);
  EXPECT_NO_THROW(Cascade{p});
}

TEST(Cascade, RunsThePiOnceEveryTenValveTicksAndHoldsItsOpening) {
  Cascade c(direct_params());
  c.activate(0.1, 0.0);
  int runs = 0;
  double held = 0.0;
  for (int k = 0; k < 100; ++k) {
    // A setpoint that changes every tick: only the ticks that run the PI may see it.
    const LawOutput out = c.tick({.rod_setpoint_m = 0.1 + 1e-6 * k, .rod_position_m = 0.1});
    EXPECT_EQ(out.cylinder_ticked, k % 10 == 0) << "tick " << k;
    if (out.cylinder_ticked) {
      ++runs;
      held = out.opening;
      EXPECT_NEAR(c.cylinder().limited_setpoint(), 0.1 + 1e-6 * k, kExact);
    }
    EXPECT_EQ(out.opening, held);
  }
  EXPECT_EQ(runs, 10);
}

// Ticks that jump by more than N: the PI runs once per change of (k − k0) / N, anchored at the
// first tick after activate(), and integrates every PI period that elapsed.
TEST(Cascade, RunsThePiOncePerWindowChangeEvenWhenTicksJumpByMoreThanN) {
  Cascade c(direct_params());
  c.activate(0.1, 0.0);
  const double e = 0.5e-3;  // constant error: setpoint 0.1005 with the rod held at 0.1
  struct Step {
    std::uint64_t tick;
    bool runs;
  };
  // Anchor k0 = 1234: windows (k − k0)/10 are 0 0 0 1 3 3 5 6 6 20.
  const Step steps[] = {{1234, true},  {1235, false}, {1243, false}, {1244, true}, {1269, true},
                        {1270, false}, {1293, true},  {1294, true},  {1295, false}, {1434, true}};
  int runs = 0;
  for (const Step& s : steps) {
    const LawOutput out = c.tick({.rod_setpoint_m = 0.1 + e, .rod_position_m = 0.1}, s.tick);
    EXPECT_EQ(out.cylinder_ticked, s.runs) << "tick " << s.tick;
    runs += out.cylinder_ticked;
  }
  EXPECT_EQ(runs, 6);
  // One period at the anchor, then windows 0 → 20: 21 PI periods of the same error in all.
  const PiParams& pi = c.params().cylinder;
  EXPECT_NEAR(c.cylinder().integral(), 21 * pi.ki * pi.period_s * e, kExact);
}

// The same span of real time, ticked every base tick or with skipped ticks, leaves the PI in the
// same state for a constant error: backward Euler integrates a constant exactly, so one step of
// m·T equals m steps of T. What remains is rounding: the reference sums n_ref terms c = Ki·T·e,
// the skipped run n_skip terms Ki·(m·T)·e of three roundings each; recursive summation of
// positive terms errs by at most (n − 1)·u·Σ|x| with u = ε/2, so together they stay within
// (n_ref + 4·n_skip)·ε·|I|.
TEST(Cascade, SkippedTicksReachTheSameStateAsEveryTickForAConstantError) {
  const double e = 0.5e-3;
  const LawInputs in{.rod_setpoint_m = 0.1 + e, .rod_position_m = 0.1};
  constexpr std::uint64_t kLast = 9999;  // one second of 100 µs ticks

  Cascade every(direct_params());
  every.activate(0.1, 0.0);
  int n_ref = 0;
  for (std::uint64_t k = 0; k <= kLast; ++k) n_ref += every.tick(in, k).cylinder_ticked;

  Cascade skipping(direct_params());
  skipping.activate(0.1, 0.0);
  int n_skip = 0;
  std::uint64_t k = 0;
  for (std::uint64_t jump = 1; k < kLast; jump = jump % 97 + 13) {  // jumps of 1 to 109 ticks
    n_skip += skipping.tick(in, k).cylinder_ticked;
    k = std::min<std::uint64_t>(k + jump, kLast);
  }
  n_skip += skipping.tick(in, kLast).cylinder_ticked;
  ASSERT_LT(n_skip, n_ref / 2);  // the schedule really skipped most PI periods

  const double integral = every.cylinder().integral();
  const PiParams& pi = every.params().cylinder;
  EXPECT_NEAR(integral, 1000 * pi.ki * pi.period_s * e, 1e-12);  // 1000 PI periods, unsaturated
  const double eps = std::numeric_limits<double>::epsilon();
  const double tol = (n_ref + 4 * n_skip) * eps * std::abs(integral);
  EXPECT_NEAR(skipping.cylinder().integral(), integral, tol);
  EXPECT_NEAR(skipping.cylinder().output(), every.cylinder().output(), tol + 4 * eps);
  EXPECT_FALSE(every.cylinder().saturated());
}

// The setpoint rate limit moves the limited setpoint by v_max·T per elapsed PI period, so a ramp
// is where it would be had every period run (rounding: n additions of v_max·T on a value of the
// order of the setpoint).
TEST(Cascade, TheSetpointRateLimitFollowsElapsedTime) {
  CascadeParams p = direct_params();
  p.cylinder.max_setpoint_rate_m_s = 0.05;
  const LawInputs in{.rod_setpoint_m = 0.2, .rod_position_m = 0.1};
  Cascade every(p), skipping(p);
  every.activate(0.1, 0.0);
  skipping.activate(0.1, 0.0);
  for (std::uint64_t k = 0; k <= 5000; ++k) every.tick(in, k);
  for (std::uint64_t k : {0, 7, 8, 260, 1999, 2000, 4321, 5000}) skipping.tick(in, k);
  // 501 PI periods of 50 µm each (the anchor's included): 25.05 mm of the 100 mm step.
  const double expected = 0.1 + 501 * 0.05 * 1e-3;
  const double tol = 501 * std::numeric_limits<double>::epsilon() * 0.2;
  EXPECT_NEAR(every.cylinder().limited_setpoint(), expected, tol);
  EXPECT_NEAR(skipping.cylinder().limited_setpoint(), expected, tol);
}

// The PI's schedule through every kind of tick, against the schedule written out with a division:
// consecutive ticks (the next-tick path), repeated and stale indices (counted as the next tick),
// jumps, open-loop ticks (the clock runs, the PI does not) and a re-activation (a new anchor). The
// PI runs when (k − k0) / N differs from its last run's, over the periods between, so with a
// constant error its integral counts the PI periods the schedule gave.
TEST(Cascade, ThePiScheduleHoldsThroughRepeatedJumpedAndOpenLoopTicks) {
  const double e = 0.5e-3;
  const LawInputs in{.rod_setpoint_m = 0.1 + e, .rod_position_m = 0.1};
  Cascade c(direct_params());
  const std::uint64_t n = c.params().valve_ticks_per_cylinder_tick;
  struct Call {
    std::uint64_t tick;
    bool open_loop = false;
    bool activate = false;
  };
  std::vector<Call> calls;
  for (std::uint64_t k = 500; k < 537; ++k) calls.push_back({k});  // consecutive, from an anchor at 500
  calls.push_back({530});                                          // stale: counts as 537
  calls.push_back({537});                                          // repeated: 538
  for (std::uint64_t k = 539; k < 545; ++k) calls.push_back({k});
  calls.push_back({571});                                          // a jump over two windows
  for (std::uint64_t k = 572; k < 575; ++k) calls.push_back({k, true});  // open loop into window 7
  for (std::uint64_t k = 575; k < 600; ++k) calls.push_back({k});  // the first catches the PI up
  for (std::uint64_t k = 600; k < 625; ++k) calls.push_back({k, true});  // open loop for two windows
  calls.push_back({625});
  calls.push_back({626});
  calls.push_back({3, false, true});  // activate, then a new anchor at 3 whatever came before
  for (std::uint64_t k = 4; k < 40; ++k) calls.push_back({k});

  c.activate(0.1, 0.0);
  bool anchored = false;
  std::uint64_t k0 = 0, last_k = 0, last_window = 0, expected_periods = 0;
  int runs = 0;
  for (std::size_t i = 0; i < calls.size(); ++i) {
    const Call& call = calls[i];
    if (call.activate) {
      c.activate(0.1, 0.0);
      anchored = false;
      expected_periods = 0;  // the integral restarts from the opening given, 0
      continue;
    }
    const std::uint64_t k = !anchored ? call.tick : call.tick > last_k ? call.tick : last_k + 1;
    if (!anchored) k0 = k;
    last_k = k;
    if (call.open_loop) {
      anchored = true;
      c.open_loop_tick(0.0, 0.0, call.tick);
      continue;
    }
    const std::uint64_t window = (k - k0) / n;
    const bool expected_run = !anchored || window != last_window;
    if (expected_run) expected_periods += anchored ? window - last_window : 1;
    anchored = true;
    if (expected_run) last_window = window;
    const LawOutput out = c.tick(in, call.tick);
    ASSERT_EQ(out.cylinder_ticked, expected_run) << "call " << i << ", tick " << call.tick;
    runs += out.cylinder_ticked;
  }
  EXPECT_GT(runs, 8);
  // The open-loop ticks leave the opening to the caller, not the integral: only the PI's periods count.
  const PiParams& pi = c.params().cylinder;
  EXPECT_NEAR(c.cylinder().integral(), static_cast<double>(expected_periods) * pi.ki * pi.period_s * e, kExact);
}

// With no tick skipped, the explicit tick index and the call counter give the same bits.
TEST(Cascade, ConsecutiveTicksAreBitIdenticalToTheCallCounter) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    Cascade counted(p), indexed(p);
    counted.activate(0.1, 1e-5, 0.1);
    indexed.activate(0.1, 1e-5, 0.1);
    for (std::uint64_t k = 0; k < 3000; ++k) {
      const LawInputs in{.rod_setpoint_m = 0.1 + 1e-3 * std::sin(1e-3 * k),
                             .rod_position_m = 0.1 + 1e-7 * k,
                             .spool_position_m = 1e-5 * std::cos(1e-3 * k)};
      const LawOutput a = counted.tick(in);
      const LawOutput b = indexed.tick(in, 777 + k);
      ASSERT_EQ(a.command, b.command) << k;
      ASSERT_EQ(a.opening, b.opening) << k;
      ASSERT_EQ(a.cylinder_ticked, b.cylinder_ticked) << k;
    }
  }
}

TEST(Cascade, DirectModeOutputsTheOpening) {
  Cascade c(direct_params());
  c.activate(0.05, 0.0);
  const LawOutput out = c.tick({.rod_setpoint_m = 0.051, .rod_position_m = 0.05, .spool_position_m = 7.0});
  EXPECT_NEAR(out.opening, (85.0 + 0.46) * 1e-3, kExact);
  EXPECT_EQ(out.command, out.opening);
}

TEST(Cascade, ActivationIsBumplessInBothModes) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    Cascade c(p);
    const double rod = 0.2, opening = 0.4;
    const double spool = opening * 1.25e-3;  // the spool sits where the opening puts it
    c.activate(rod, spool, opening);
    const LawOutput out = c.tick({.rod_setpoint_m = rod, .rod_position_m = rod, .spool_position_m = spool});
    EXPECT_NEAR(out.opening, opening, kExact);
    if (p.drive == ValveDrive::direct) {
      EXPECT_NEAR(out.command, opening, kExact);
    } else {
      // Spool on its reference and at rest: only bias and feedforward remain.
      EXPECT_NEAR(out.command, 1.2 + 250.0 * spool, kExact);
    }
  }
}

TEST(Cascade, OpeningMapsLinearlyOntoTheSpoolStroke) {
  Cascade c(proportional_params());
  for (const double opening : {-1.0, -0.5, 0.0, 0.25, 1.0}) {
    c.activate(0.1, 0.0, opening);
    const LawOutput out = c.tick({.rod_setpoint_m = 0.1, .rod_position_m = 0.1});
    EXPECT_NEAR(out.spool_reference_m, opening * 1.25e-3, kExact);
    // The spool sits at zero: the valve law sees the reference as its error.
    EXPECT_NEAR(c.valve().error(), opening * 1.25e-3, kExact);
  }
}

TEST(Cascade, TicksWithoutAllocating) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    Cascade c(p);
    const long before = g_allocations.load();
    c.activate(0.1, 0.0);
    double sum = 0.0;
    for (int k = 0; k < 10000; ++k) {
      sum += c.tick({.rod_setpoint_m = 0.12, .rod_position_m = 0.1 + 1e-7 * k, .spool_position_m = 1e-5}).command;
    }
    EXPECT_EQ(g_allocations.load(), before);
    EXPECT_TRUE(std::isfinite(sum));
  }
}

// A small closed loop for the cascade to run in: the spool follows the current the valve law's
// feed-forward expects (bias 1.2 A, 250 A/m) through a 5 ms lag, and the rod moves at 0.1 m/s per
// unit of the opening the spool makes (direct drive: per unit of the commanded opening). The rod
// follows a 1 Hz sine of 10 mm, so the opening and the current move on every tick.
struct LoopRun {
  explicit LoopRun(const CascadeParams& p) : cascade(p) { cascade.activate(rod, spool); }

  LawOutput tick() {
    const double setpoint = 0.1 + 0.01 * std::sin(2.0 * 3.141592653589793 * t);
    const LawOutput out = cascade.tick({.rod_setpoint_m = setpoint, .rod_position_m = rod,
                                            .spool_position_m = spool});
    const double dt = cascade.params().valve.period_s;
    double opening = out.command;
    if (cascade.params().drive == ValveDrive::proportional) {
      spool += dt / 5e-3 * ((out.command - 1.2) / 250.0 - spool);
      opening = spool / cascade.params().spool_at_full_opening_m;
    }
    rod += dt * 0.1 * opening;
    t += dt;
    return out;
  }

  Cascade cascade;
  double rod = 0.1;
  double spool = 0.0;
  double t = 0.0;
};

// The largest change of the command and of the opening between consecutive ticks over a window.
struct Steps {
  double command = 0.0;
  double opening = 0.0;
};

// The steps of a run around a change between two ticks: the largest over the 100 tick pairs
// before it, the step across it, and the largest over the 1000 pairs after it (the pair across
// the change not counted there). A stiffer PI makes larger steps of its own, so "no more than two
// ticks without a change" takes the larger of the two windows: with the old gains or the new.
struct AroundChange {
  Steps before;
  Steps at;
  Steps after;
  // What two ticks without a change differ by, with the old gains or with the new ones.
  [[nodiscard]] Steps bound() const {
    return {std::max(before.command, after.command), std::max(before.opening, after.opening)};
  }
};

// Runs 2000 ticks to get the loop going, then 100 ticks, `change`, and 1001 ticks. The change is
// made just before a tick that runs the PI, so the new gains act at once.
AroundChange run_around_change(LoopRun& run, const std::function<void(LoopRun&)>& change) {
  LawOutput last{};
  for (int k = 0; k < 2000; ++k) last = run.tick();
  const auto step = [&last](const LawOutput& out, Steps& into) {
    into.command = std::max(into.command, std::abs(out.command - last.command));
    into.opening = std::max(into.opening, std::abs(out.opening - last.opening));
    last = out;
  };
  AroundChange r;
  for (int k = 0; k < 100; ++k) step(run.tick(), r.before);
  change(run);
  const LawOutput first = run.tick();
  EXPECT_TRUE(first.cylinder_ticked);  // the new gains act on this very tick
  step(first, r.at);
  for (int k = 0; k < 1000; ++k) step(run.tick(), r.after);
  return r;
}

// Both ways: a stiffer PI (whose own steps are larger) and a softer one.
TEST(Cascade, GainChangeIsBumplessOnBothDrives) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    for (const double factor : {2.0, 0.5}) {
      SCOPED_TRACE(std::string(p.drive == ValveDrive::direct ? "direct" : "proportional") + ", kp x" +
                   std::to_string(factor));
      LoopRun run(p);
      const AroundChange r = run_around_change(run, [&](LoopRun& l) {
        const Eigen::Vector4d predictor = l.cascade.predictor().state();
        const double valve_integral = l.cascade.valve().integral();
        const double opening = l.cascade.cylinder().output();
        ASSERT_TRUE(l.cascade.set_cylinder_gains(factor * 85.0, 460.0));
        // Nothing but the gains moved: the opening held, the valve loop's states.
        EXPECT_EQ(l.cascade.cylinder().output(), opening);
        EXPECT_EQ(l.cascade.predictor().state(), predictor);
        EXPECT_EQ(l.cascade.valve().integral(), valve_integral);
      });
      ASSERT_GT(r.before.opening, 0.0);  // the loop was moving: the bound is not zero
      ASSERT_GT(r.before.command, 0.0);
      EXPECT_LE(r.at.opening, r.bound().opening);
      EXPECT_LE(r.at.command, r.bound().command);
      EXPECT_EQ(run.cascade.params().cylinder.kp, factor * 85.0);
      EXPECT_EQ(run.cascade.params().cylinder.ki, 460.0);
      EXPECT_EQ(run.cascade.cylinder().params().kp, factor * 85.0);
      if (factor < 1.0) {
        // A softer PI makes smaller steps of its own: the step is within the old ones alone.
        EXPECT_LE(r.at.opening, r.before.opening);
        EXPECT_LE(r.at.command, r.before.command);
      }
      if (p.drive == ValveDrive::proportional) {
        std::printf("proportional, kp x%g: current step at the change %.4g A; without a change up to %.4g A "
                    "before, %.4g A after\n",
                    factor, r.at.command, r.before.command, r.after.command);
      }
    }
  }
}

// What the gain change replaces: a cascade rebuilt with the new gains and re-activated at the
// measured state starts its predictor at rest and its valve integrator empty, so on the
// proportional drive the current steps by more than the loop moves it in a tick. This is what
// keeps the bound above from passing by accident.
TEST(Cascade, RebuildingTheCascadeAtAGainChangeStepsTheCurrent) {
  LoopRun run(proportional_params());
  const AroundChange r = run_around_change(run, [](LoopRun& l) {
    CascadeParams p = l.cascade.params();
    p.cylinder.kp = 4.0 * 85.0;
    p.cylinder.ki = 460.0 / 4.0;
    const double opening = l.cascade.cylinder().output();
    l.cascade = Cascade(p);
    l.cascade.activate(l.rod, l.spool, opening);
  });
  std::printf("rebuilt cascade, kp x4: current step at the change %.4g A; without a change up to %.4g A\n",
              r.at.command, r.bound().command);
  EXPECT_GT(r.at.command, r.bound().command);
}

TEST(Cascade, GainChangeRefusesBadGainsAndAllocatesNothing) {
  Cascade c(proportional_params());
  c.activate(0.1, 0.0, 0.3);
  EXPECT_FALSE(c.set_cylinder_gains(-1.0, 460.0));
  EXPECT_FALSE(c.set_cylinder_gains(85.0, std::nan("")));
  EXPECT_FALSE(c.set_cylinder_gains(std::numeric_limits<double>::infinity(), 460.0));
  EXPECT_EQ(c.params().cylinder.kp, 85.0);
  EXPECT_EQ(c.cylinder().params().ki, 460.0);
  EXPECT_EQ(c.cylinder().output(), 0.3);
  const long before = g_allocations.load();
  EXPECT_TRUE(c.set_cylinder_gains(40.0, 100.0));
  EXPECT_EQ(g_allocations.load(), before);
}

TEST(Cascade, RejectsInconsistentRates) {
  CascadeParams p;
  p.cylinder.period_s = 2e-3;
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
  p.valve_ticks_per_cylinder_tick = 20;
  EXPECT_NO_THROW(Cascade{p});
  p.valve_ticks_per_cylinder_tick = 0;
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
