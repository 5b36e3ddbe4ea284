// The cascade's valve stage on the model predictor (control/cascade.hpp; the model-predictor,
// damped and time-optimal steps of identified_valve_law): with params.valve.model_predictor enabled
// the cascade's commands are, bit for bit, those of a ValveLaw behind a ValveModelPredictor run by
// hand on the same references and LVDT samples (the loop of hsa-analyze experiment valve), through
// tick(), open_loop_tick(), skipped periods and activate(); and nothing in a tick allocates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

#include "control/cascade.hpp"
#include "control/valve_law.hpp"
#include "control/valve_model_predictor.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

// An identified valve as identified_valve() gives it for the paper's valve (round figures).
IdentifiedValve paper_like() {
  return {.gain_m_per_a = 1.0 / 548.3, .rest_position_m = -2.5e-3, .natural_frequency_hz = 50.0,
          .damping_ratio = 0.3, .magnetic_lag_s = 1.5e-3, .width_a = 0.3, .delay_s = 0.5e-3, .current_max_a = 3.0};
}

CascadeParams cascade_for(ValveLawStep step) {
  CascadeParams p;
  p.valve = identified_valve_law(paper_like(), step);
  return p;
}

// A spool for the loop to move: a 2 ms lag towards the position the current holds it at (the
// identified spring), so that the LVDT sample, and with it the predictor's input, changes on every
// tick as the commands do.
struct Spool {
  double x = 0.0;
  void follow(double current_a) {
    const IdentifiedValve v = paper_like();
    x += (1e-4 / 2e-3) * (v.rest_position_m + v.gain_m_per_a * (current_a - 0.5 * v.width_a) - x);
  }
};

// The hand-run valve loop of hsa-analyze experiment valve: law.update(r, predictor.update(y)),
// then predictor.commanded(I).
struct ByHand {
  explicit ByHand(const ValveLawParams& p) : predictor(p.model_predictor, p.period_s), law(p) {}
  void reset(double spool_m) {
    predictor.reset(spool_m);
    law.reset();
  }
  double update(double reference_m, double spool_m, std::uint64_t elapsed = 1) {
    const double current = law.update(reference_m, predictor.update(spool_m), elapsed);
    predictor.commanded(current);
    return current;
  }
  ValveModelPredictor predictor;
  ValveLaw law;
};

TEST(CascadeModelPredictor, RunsOnlyWhenTheLawEnablesIt) {
  EXPECT_EQ(Cascade(cascade_for(ValveLawStep::model_inverse)).model_predictor(), nullptr);
  for (ValveLawStep step : {ValveLawStep::model_predictor, ValveLawStep::damped, ValveLawStep::time_optimal})
    EXPECT_NE(Cascade(cascade_for(step)).model_predictor(), nullptr);
  // A direct drive has no valve loop to run it in.
  CascadeParams direct = cascade_for(ValveLawStep::damped);
  direct.drive = ValveDrive::direct;
  EXPECT_EQ(Cascade(direct).model_predictor(), nullptr);
}

TEST(CascadeModelPredictor, AModelThePredictorRefusesIsRefusedAtConstruction) {
  CascadeParams p = cascade_for(ValveLawStep::model_predictor);
  p.valve.model_predictor.valve.delay_s = 17 * p.valve.period_s;  // beyond kMaxDelaySamples
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
  p.valve.model_predictor.valve.delay_s = 0.5e-3;
  p.valve.model_predictor.gamma[2] = 0.0;
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
}

// The rod follows a 5 Hz sine of 5 mm about a rod that does not move, so the PI's opening (and with
// it the spool reference) moves on every cylinder tick; the cascade's own spool reference is fed to
// the hand-run loop, which checks the valve stage alone (the PI is test_cascade.cpp's).
TEST(CascadeModelPredictor, TicksGiveTheCommandsOfTheLawBehindTheModelPredictorBitForBit) {
  for (ValveLawStep step : {ValveLawStep::model_predictor, ValveLawStep::damped, ValveLawStep::time_optimal}) {
    SCOPED_TRACE(static_cast<int>(step));
    const CascadeParams p = cascade_for(step);
    Cascade cascade(p);
    ByHand hand(p.valve);
    Spool spool{.x = -1e-4};
    cascade.activate(0.1, spool.x);
    hand.reset(spool.x);
    int moving = 0;
    for (std::uint64_t k = 0; k < 4000; ++k) {
      const double t = 1e-4 * static_cast<double>(k);
      const LawOutput out = cascade.tick(
          {.rod_setpoint_m = 0.1 + 5e-3 * std::sin(2.0 * std::numbers::pi * 5.0 * t), .rod_position_m = 0.1,
           .spool_position_m = spool.x},
          k);
      const double expected = hand.update(out.spool_reference_m, spool.x);
      ASSERT_EQ(out.command, expected) << "tick " << k;
      if (out.command != hand.law.params().bias_current_a) ++moving;
      spool.follow(out.command);
    }
    EXPECT_GT(moving, 3000);  // the commands moved: the comparison was not of constants
  }
}

// A step of the opening through open_loop_tick: on the time-optimal law it starts a move, which runs
// on the law's own model; the model predictor is fed the move's currents as the law's. Skipped
// periods (k jumping by 3) step the model predictor over the missed ones with the measurement and
// the last current held.
TEST(CascadeModelPredictor, OpenLoopStepsAndSkippedPeriodsMatchTheHandRunLoop) {
  const CascadeParams p = cascade_for(ValveLawStep::time_optimal);
  Cascade cascade(p);
  ByHand hand(p.valve);
  Spool spool{.x = 0.0};
  cascade.activate(0.1, spool.x);
  hand.reset(spool.x);
  std::uint64_t k = 0;
  for (int i = 0; i < 3000; ++i) {
    const double opening = (i / 500) % 2 == 0 ? 0.6 : -0.6;
    const std::uint64_t elapsed = i > 0 && i % 97 == 0 ? 3 : 1;
    k += elapsed;
    const double command = cascade.open_loop_tick(opening, spool.x, k).command;
    if (elapsed > 1) {
      const double held = hand.law.current();
      for (std::uint64_t m = 1; m < elapsed; ++m) {
        (void)hand.predictor.update(spool.x);
        hand.predictor.commanded(held);
      }
    }
    const double expected = hand.update(opening * p.spool_at_full_opening_m, spool.x, elapsed);
    ASSERT_EQ(command, expected) << "sample " << i;
    spool.follow(command);
  }
  EXPECT_GE(hand.law.time_optimal().moves(), 5u);  // every step of the opening was a move
  EXPECT_EQ(cascade.valve().time_optimal().moves(), hand.law.time_optimal().moves());
}

// activate() restarts the model predictor at rest on the spool, as it does the paper's: after a run,
// the re-activated cascade gives the commands of its law (as activate() left it) behind a model
// predictor started afresh on the spool.
TEST(CascadeModelPredictor, ActivationRestartsTheModelPredictor) {
  const CascadeParams p = cascade_for(ValveLawStep::damped);
  Cascade cascade(p);
  Spool spool{.x = 0.0};
  cascade.activate(0.1, spool.x);
  for (std::uint64_t k = 0; k < 500; ++k) {
    const LawInputs in{.rod_setpoint_m = 0.105, .rod_position_m = 0.1, .spool_position_m = spool.x};
    spool.follow(cascade.tick(in, k).command);
  }
  cascade.activate(0.1, spool.x);
  ByHand hand(p.valve);
  hand.law = cascade.valve();  // its dither phase runs on through activate()
  hand.predictor.reset(spool.x);
  for (std::uint64_t k = 0; k < 200; ++k) {
    const LawOutput out =
        cascade.tick({.rod_setpoint_m = 0.102, .rod_position_m = 0.1, .spool_position_m = spool.x}, 1000 + k);
    ASSERT_EQ(out.command, hand.update(out.spool_reference_m, spool.x)) << "tick " << k;
    spool.follow(out.command);
  }
}

TEST(CascadeModelPredictor, TicksWithoutAllocating) {
  for (ValveLawStep step : {ValveLawStep::model_predictor, ValveLawStep::time_optimal}) {
    Cascade c(cascade_for(step));
    const long before = test::thread_allocations();
    c.activate(0.1, 0.0);
    double sum = 0.0;
    for (std::uint64_t k = 0; k < 10000; ++k) {
      // A jump of the setpoint, skipped periods and open-loop ticks: every path of the valve stage.
      const double setpoint = k < 5000 ? 0.12 : 0.08;
      const std::uint64_t at = k + k / 1000;
      sum += k % 2000 == 1999 ? c.open_loop_tick(0.5, 1e-5, at).command
                              : c.tick({.rod_setpoint_m = setpoint, .rod_position_m = 0.1, .spool_position_m = 1e-5},
                                       at).command;
    }
    EXPECT_EQ(test::thread_allocations(), before);
    EXPECT_TRUE(std::isfinite(sum));
  }
}

}  // namespace
}  // namespace hsa::control
