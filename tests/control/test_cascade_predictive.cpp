// The cascade's valve stage on the predictive law (control/cascade.hpp, valve_predictive.hpp): with
// params.valve.predictive enabled the cascade's commands are, bit for bit, those of a
// ValvePredictiveLaw run by hand on the same spool references and LVDT samples (the loop of
// hsa-analyze experiment valve --valve-law predictive, the reference averaged over the PI's
// period), through tick(), open_loop_tick(), skipped periods and activate(); the axis's saturation is the law's; and nothing in a tick allocates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>

#include "control/cascade.hpp"
#include "control/valve_predictive_design.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

// The paper's valve as the fit's model describes it, with the settings the design picks there.
CascadeParams predictive_cascade() {
  CascadeParams p;
  ValvePredictiveValve valve;
  valve.regulator_delay_s = 2e-4;
  valve.current_max_a = 3.0;
  ValvePredictiveSettings s;
  s.preview_samples = 28;
  s.rate_weight_m2_per_a2 = 2e-11;
  s.dither_fraction = 0.75;
  s.disturbance_walk_a = 1e-6;
  s.headroom_fraction = 0.5;
  p.valve.predictive = valve_predictive_params(valve, p.valve.period_s, 2500.0, s);
  return p;
}

// The law the cascade runs: its reference averaged over the PI's period.
ValvePredictiveLaw by_hand(const CascadeParams& p) {
  ValvePredictiveParams law = p.valve.predictive;
  law.reference_window_samples = static_cast<int>(p.valve_ticks_per_cylinder_tick);
  return ValvePredictiveLaw(law);
}

// A spool for the loop to move: a 2 ms lag towards where the current holds it (the model's g, X_min
// and half its play), so that the LVDT sample changes on every tick as the commands do.
struct Spool {
  double x = 0.0;
  void follow(double current_a) { x += (1e-4 / 2e-3) * (-2.5e-3 + 1.8e-3 * (current_a - 0.15) - x); }
};

TEST(CascadePredictive, RunsOnlyWhenTheLawEnablesIt) {
  EXPECT_EQ(Cascade(CascadeParams{}).predictive(), nullptr);
  CascadeParams p = predictive_cascade();
  EXPECT_NE(Cascade(p).predictive(), nullptr);
  p.drive = ValveDrive::direct;  // no valve loop to run it in
  EXPECT_EQ(Cascade(p).predictive(), nullptr);
}

// The rod follows a 5 Hz sine of 5 mm about a rod that does not move, so the PI's opening moves on
// every cylinder tick; every 7th period is skipped and every 500th tick is an open-loop jump.
TEST(CascadePredictive, TicksGiveTheCommandsOfTheLawBitForBit) {
  const CascadeParams p = predictive_cascade();
  Cascade cascade(p);
  ValvePredictiveLaw hand = by_hand(p);
  Spool spool{.x = -1e-4};
  cascade.activate(0.1, spool.x);
  hand.reset(spool.x, spool.x);
  std::uint64_t k = 0;
  int moving = 0, skipped = 0;
  for (int i = 0; i < 4000; ++i) {
    const std::uint64_t elapsed = i > 0 && i % 7 == 0 ? 2 : 1;
    k += elapsed;
    skipped += elapsed > 1;
    const double t = 1e-4 * static_cast<double>(k);
    LawOutput out;
    if (i % 500 == 499) {
      out = cascade.open_loop_tick(0.6, spool.x, k);
    } else {
      out = cascade.tick({.rod_setpoint_m = 0.1 + 5e-3 * std::sin(2.0 * std::numbers::pi * 5.0 * t),
                          .rod_position_m = 0.1, .spool_position_m = spool.x},
                         k);
    }
    const double expected = hand.update(out.spool_reference_m, spool.x, elapsed);
    ASSERT_EQ(out.command, expected) << "sample " << i;
    ASSERT_EQ(cascade.valve_saturated(), hand.saturated()) << "sample " << i;
    if (std::abs(out.command - 1.5) > 0.3) ++moving;
    spool.follow(out.command);
  }
  EXPECT_GT(moving, 100);  // the commands moved: the comparison was not of constants
  EXPECT_GT(skipped, 500);
}

// A full-stroke jump of the opening asks for more current than the box holds: the cascade's
// saturation (what the axis's current_saturated fault reads) is the predictive law's, not eq 31's
// idle law's; activate() restarts the law at rest on the spool.
TEST(CascadePredictive, SaturationAndActivationAreThePredictiveLaws) {
  const CascadeParams p = predictive_cascade();
  Cascade cascade(p);
  Spool spool{.x = -1.2e-3};
  cascade.activate(0.1, spool.x);
  int saturated = 0;
  for (std::uint64_t k = 0; k < 300; ++k) {
    spool.follow(cascade.open_loop_tick(1.0, spool.x, k).command);
    saturated += cascade.valve_saturated();
    EXPECT_FALSE(cascade.valve().saturated());
  }
  EXPECT_GT(saturated, 5);
  cascade.activate(0.1, spool.x);
  ValvePredictiveLaw hand = by_hand(p);
  hand.reset(spool.x, spool.x);
  for (std::uint64_t k = 0; k < 200; ++k) {
    const LawOutput out = cascade.open_loop_tick(-0.2, spool.x, 1000 + k);
    ASSERT_EQ(out.command, hand.update(out.spool_reference_m, spool.x)) << "tick " << k;
    spool.follow(out.command);
  }
}

TEST(CascadePredictive, TicksWithoutAllocating) {
  Cascade c(predictive_cascade());
  const long before = test::thread_allocations();
  c.activate(0.1, 0.0);
  double sum = 0.0;
  for (std::uint64_t k = 0; k < 10000; ++k) {
    // A jump of the setpoint, skipped periods and open-loop ticks: every path of the valve stage.
    const double setpoint = k < 5000 ? 0.12 : 0.08;
    const std::uint64_t at = k + k / 1000;
    sum += k % 2000 == 1999
               ? c.open_loop_tick(0.5, 1e-5, at).command
               : c.tick({.rod_setpoint_m = setpoint, .rod_position_m = 0.1, .spool_position_m = 1e-5}, at).command;
  }
  EXPECT_EQ(test::thread_allocations(), before);
  EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace hsa::control
