// The control-law seam: the registry knows the laws by name, each law's open-loop path runs the
// parts its position mode runs beneath the PI, and runtime gains are checked against the law's
// bounds and taken without a step.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/law_registry.hpp"
#include "control/laws/direct_servo/direct_servo_law.hpp"
#include "control/laws/proportional_cascade/proportional_cascade_law.hpp"

namespace hsa::control {
namespace {

CascadeParams proportional_params() {
  CascadeParams c;
  c.drive = ValveDrive::proportional;
  c.valve = simulated_proportional_valve_law();
  return c;
}

constexpr GainBounds kBounds{.max_kp = 170.0, .max_ki = 920.0};

TEST(LawRegistry, FindsEachLawByTheNameItReports) {
  ASSERT_EQ(registered_laws().size(), 2u);
  for (const LawRegistration& r : registered_laws()) {
    EXPECT_EQ(find_law(r.name), &r);
    ASSERT_FALSE(r.tables.empty());
    EXPECT_EQ(r.tables.front(), "pi");
  }
  EXPECT_NE(find_law("direct"), nullptr);
  EXPECT_NE(find_law("proportional"), nullptr);
  EXPECT_EQ(find_law("banana"), nullptr);
  EXPECT_EQ(find_law(""), nullptr);
}

// Open loop on a proportional valve closes the spool loop with the same state predictor and valve
// law the cascade runs beneath the PI: the command equals those parts run by hand on the
// reference u · spool_at_full_opening_m, tick for tick, skipped ticks included.
TEST(ProportionalCascadeLaw, OpenLoopRunsTheCascadesOwnValveStage) {
  const CascadeParams params = proportional_params();
  ProportionalCascadeLaw law(params, kBounds);
  StatePredictor predictor(params.predictor, params.valve.period_s);
  ValveLaw valve(params.valve);
  law.activate(0.15, -0.2e-3, 0.0);
  predictor.reset(-0.2e-3);
  valve.reset();
  const double opening = 0.3;
  const std::uint64_t ticks[] = {100, 101, 102, 105, 106, 120};
  std::uint64_t last = ticks[0];
  for (const std::uint64_t k : ticks) {
    const std::uint64_t elapsed = k == ticks[0] ? 1 : k - last;
    last = k;
    const double spool = -0.2e-3 + 1e-6 * static_cast<double>(k - ticks[0]);
    const LawOutput out = law.open_loop_tick(opening, spool, k);
    const double reference = opening * params.spool_at_full_opening_m;
    EXPECT_EQ(out.spool_reference_m, reference);
    EXPECT_EQ(out.opening, opening);
    EXPECT_EQ(out.command, valve.update(reference, predictor.update(spool, elapsed), elapsed)) << "tick " << k;
  }
  EXPECT_EQ(law.cascade().predictor().state(), predictor.state());
}

TEST(DirectServoLaw, OpenLoopSendsTheOpeningAsTheCommand) {
  PiParams pi;
  pi.max_setpoint_rate_m_s = 0.1;
  DirectServoLaw law(pi, 10, kBounds);
  EXPECT_FALSE(law.needs_spool());
  EXPECT_EQ(law.null_command(), 0.0);
  law.activate(0.1, 0.0, 0.0);
  for (const double u : {0.25, -0.5, 1.0}) EXPECT_EQ(law.open_loop_tick(u, 0.0, 0).command, u);
}

// saturated() judges the command the law writes: on a proportional valve the solenoid current
// the valve law clamps to [0, I_max], not the PI's opening beneath it.
TEST(ProportionalCascadeLaw, SaturatedJudgesTheCurrentAgainstItsLimitNotThePisOpening) {
  CascadeParams params = proportional_params();
  params.cylinder.kp = 10.0;
  params.cylinder.ki = 0.0;
  params.cylinder.max_setpoint_rate_m_s = 100.0;
  // A stiff spool loop: 1 µm of spool error is 1 A, so a small opening clamps the current.
  params.valve.bias_current_a = 0.5;
  params.valve.max_current_a = 1.0;
  params.valve.proportional_a_per_m = 1e6;
  params.valve.dead_band_compensation_a = 0.0;
  params.valve.dither_amplitude_a = 0.0;
  {
    ProportionalCascadeLaw law(params, kBounds);
    law.activate(0.150, 0.0, 0.0);
    // 1 mm of rod error: an opening of 0.01, far inside the PI's limit, asks 12.5 µm of spool.
    LawOutput out{};
    for (std::uint64_t k = 0; k < 20; ++k) out = law.tick({0.151, 0.150, 0.0, 0.0}, k);
    ASSERT_LT(std::abs(out.opening), 0.5);
    EXPECT_EQ(out.command, params.valve.max_current_a);
    EXPECT_TRUE(law.cascade().valve().saturated());
    EXPECT_TRUE(law.saturated()) << "the current sits at I_max";
  }
  // The reverse: the PI's opening clamps at its limit while the valve law, with no gains but its
  // bias, holds the current at I0, inside [0, I_max].
  params.valve.proportional_a_per_m = 0.0;
  params.valve.feedforward_a_per_m = 0.0;
  params.valve.integral_a_per_m_s = 0.0;
  params.valve.velocity_a_per_m_s = 0.0;
  params.valve.acceleration_a_per_m_s2 = 0.0;
  ProportionalCascadeLaw law(params, kBounds);
  law.activate(0.150, 0.0, 0.0);
  LawOutput out{};
  for (std::uint64_t k = 0; k < 20; ++k) out = law.tick({0.290, 0.150, 0.0, 0.0}, k);
  ASSERT_TRUE(law.cascade().cylinder().saturated());
  EXPECT_EQ(out.command, params.valve.bias_current_a);
  EXPECT_FALSE(law.saturated()) << "the current is not at its limit";
}

// A servo-valve's command is the PI's opening itself: saturated() judges it against the PI's
// output limit.
TEST(DirectServoLaw, SaturatedJudgesTheOpeningItWritesAgainstTheOutputLimit) {
  PiParams pi;
  pi.kp = 10.0;
  pi.ki = 0.0;
  pi.max_setpoint_rate_m_s = 100.0;
  DirectServoLaw law(pi, 10, kBounds);
  law.activate(0.150, 0.0, 0.0);
  LawOutput out = law.tick({0.151, 0.150, 0.0, 0.0}, 0);
  EXPECT_FALSE(law.saturated());
  for (std::uint64_t k = 10; k < 200; k += 10) out = law.tick({0.290, 0.150, 0.0, 0.0}, k);
  EXPECT_EQ(std::abs(out.command), pi.output_limit);
  EXPECT_TRUE(law.saturated());
}

TEST(PiCascadeLaw, GainsOutsideTheBoundsAreRefusedWithTheReasonAndChangeNothing) {
  ProportionalCascadeLaw law(proportional_params(), kBounds);
  const auto refusal = [&](RuntimeGains g) {
    try {
      law.check_gains(g);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  using ::testing::HasSubstr;
  EXPECT_THAT(refusal({170.5, 0.0}), HasSubstr("kp 170.5 is outside (0, max_kp 170]"));
  EXPECT_THAT(refusal({85.0, 921.0}), HasSubstr("ki 921 is outside [0, max_ki 920]"));
  EXPECT_THAT(refusal({std::nan(""), 1.0}), HasSubstr("finite"));
  EXPECT_EQ(refusal({170.0, 0.0}), "accepted");
  EXPECT_EQ(law.gains(), (RuntimeGains{85.0, 460.0}));
}

TEST(PiCascadeLaw, ConfiguredGainsMustLieWithinFiniteBounds) {
  EXPECT_THROW(ProportionalCascadeLaw(proportional_params(), {.max_kp = 50.0, .max_ki = 1000.0}),
               std::invalid_argument);
  EXPECT_THROW(ProportionalCascadeLaw(proportional_params(), {.max_kp = INFINITY, .max_ki = 1000.0}),
               std::invalid_argument);
  EXPECT_NO_THROW(ProportionalCascadeLaw(proportional_params(), {.max_kp = 85.0, .max_ki = 460.0}));
}

// What the configuration checks a safe command against: closed, within the band of full scale.
TEST(ControlLaws, SafeCommandsMustCloseTheValve) {
  const ProportionalCascadeLaw proportional(proportional_params(), kBounds);
  const double bias = proportional_params().valve.bias_current_a;
  EXPECT_EQ(proportional.null_command(), bias);
  EXPECT_EQ(proportional.safe_command_refusal(bias, 0.02), "");
  EXPECT_EQ(proportional.safe_command_refusal(0.0, 0.02), "");  // de-energized: spring-centred
  EXPECT_THAT(proportional.safe_command_refusal(bias + 0.5, 0.02), ::testing::HasSubstr("closes the valve"));
  const DirectServoLaw direct(PiParams{.max_setpoint_rate_m_s = 0.1}, 10, kBounds);
  EXPECT_EQ(direct.safe_command_refusal(0.01, 0.02), "");
  EXPECT_EQ(direct.safe_command_refusal(0.03, 0.02), "a finite number in [-0.02, 0.02]");
}

// A clone is a new law with the same parameters, not yet activated, and independent of its source.
TEST(ControlLaws, ACloneRunsAsItsSourceWouldFromTheSameStart) {
  ProportionalCascadeLaw law(proportional_params(), kBounds);
  const std::unique_ptr<ControlLaw> copy = law.clone();
  EXPECT_EQ(copy->name(), "proportional");
  law.activate(0.1, 0.0, 0.0);
  copy->activate(0.1, 0.0, 0.0);
  for (std::uint64_t k = 0; k < 50; ++k) {
    const LawInputs in{.rod_setpoint_m = 0.12, .rod_position_m = 0.1, .spool_position_m = 0.0};
    EXPECT_EQ(law.tick(in, k).command, copy->tick(in, k).command);
  }
  law.set_gains({40.0, 100.0});
  EXPECT_EQ(copy->gains(), (RuntimeGains{85.0, 460.0}));
}

}  // namespace
}  // namespace hsa::control
