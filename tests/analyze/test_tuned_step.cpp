// The commissioning chain identify → gate → tune → step, closed on the simulated rig in lockstep
// (tools/hsa_analyze/experiments.hpp: the real PI at 1 kHz on the nonlinear rig at 10 kHz, no
// clock). Gains tuned by control/pi_tuning on a plant set must
//   - pass the gate they were tuned against (control/gain_gate),
//   - move the rig through Puglisi et al. (2015)'s Exp. 1 (a 10 mm step at 50/150/250 mm under
//     0/3/6 kg) within the paper's band: 2 % settling ≤ 0.6 s, overshoot ≤ 30 % (less than the
//     band's 10 % floor is a better-damped step, not a miss), no sustained oscillation;
//   - and do what the tuning predicted: each measured step within the tolerances below of the
//     linear loop (eq 41 closed by the PI) on the set's plant nearest the working point.
// Twice: on the paper's rig with gains tuned on its Table A3, and on a rig variant nobody tuned
// for (32 mm bore, 40 bar, 8 L/min, twice the seal friction) whose plant set is identified here
// from simulated identification runs (identification_run.hpp), as `hsa-analyze identify --set`
// reads them. The gate must also refuse gains that are unstable on the identified set, and the
// rig must confirm that they are.
//
// Two findings the linear loop cannot show, pinned rather than loosened:
//   - the integral dead band is part of the tuning: with the experiments' 5 µm (chosen with the
//     paper's kp 85) the tuned gains leave the unloaded rod hunting at rest on both rigs (24 and
//     37 µm peak to peak on the paper's rig at 50 and 150 mm; 29 and 46 µm on the variant);
//     with 10 µm both come to rest (kTunedIntegralDeadBandM);
//   - on the variant the tuned kp (111 /m) asks the 10 mm step for an opening of 1.11; the valve
//     clamps it at 1 and the rig overshoots about 5 points less than the linear prediction, which
//     knows no clamp: the prediction is an upper bound there, and exact on a step that does not
//     saturate the valve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "control/gain_gate.hpp"
#include "control/identification/identify_set.hpp"
#include "control/pi_tuning.hpp"
#include "tests/analyze/identification_run.hpp"
#include "tools/hsa_analyze/experiments.hpp"
#include "tools/hsa_analyze/step_prediction.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"

namespace hsa {
namespace {

using analyze::StepMetrics;
using analyze::StepPrediction;

// The paper's band for the step (docs/experiments.md).
constexpr double kMaxOvershootPct = 30.0;
constexpr double kMaxSettlingS = 0.6;

// How far a measured step may lie from the linear prediction. What the linear loop leaves out: the
// seals' dry friction and the integral's ±5 µm dead band (the last 0.05 % of a 10 mm step), the
// 1 µm encoder, the valve's own dynamics and the rig's nonlinear orifice and chambers around the
// linear point, and, on the paper's rig, the distance from the case to the nearest Table A3 plant
// (50 and 250 mm are read from 60 and 240 mm). Set from the paper's own gains on its own rig
// (the first test below), before any tuned gains ran: their nine steps overshoot 0.8–1.4 points
// more than Table A3 predicts and settle within 0.013 s of it. The tolerances leave some room
// over that, not a factor: a 2 % settling time jumps when a wiggle of the response grazes the band.
constexpr double kOvershootTolerancePts = 2.0;
constexpr double kSettlingToleranceS = 0.05;

// The integral dead band the tuned gains run with. The seals' static friction holds the rod where
// the P term's opening, kp·e, no longer breaks it free; a lower kp sticks it farther from the
// target, and a stuck error outside the band winds the integrator up until the rod slips past
// and sticks on the other side (docs/experiments.md, "Why the rod hunted"). 5 µm rests the paper's kp 85;
// 6.8 µm (5 µm · 85/62.8) still hunts at 150 mm, 0 kg (25 µm); 10 µm rests both rigs' tuned gains.
constexpr double kTunedIntegralDeadBandM = 10e-6;

struct Case {
  StepMetrics measured;
  StepPrediction predicted;
};

// The paper's nine cases with `gains` on `rig`, each beside its prediction on `set`, printed.
std::vector<Case> nine_steps(const sim::RigConfig& rig, const control::GatePlantSet& set,
                             const control::PiGainsSi& gains, const std::string& what,
                             double dead_band_m = kTunedIntegralDeadBandM) {
  std::printf("%s: kp %.1f /m, ki %.1f /(m s), predicted on %s\n", what.c_str(), gains.kp, gains.ki, set.name.c_str());
  std::vector<Case> cases;
  for (double position : analyze::kStepPositionsM) {
    for (double load : analyze::kLoadsKg) {
      analyze::Setup setup;
      setup.rig = rig;
      setup.pi.kp = gains.kp;
      setup.pi.ki = gains.ki;
      setup.pi.integral_dead_band_m = dead_band_m;
      const Case c{analyze::run_step(position, load, setup), analyze::predict_step(set, position, load, gains)};
      std::printf("  %3.0f mm %1.0f kg  overshoot %5.2f %% (predicted %5.2f %%)  settling %.3f s (predicted %.3f s)"
                  "  rest p-p %.0f µm  [%s]\n",
                  position * 1e3, load, c.measured.overshoot_pct, c.predicted.overshoot_pct, c.measured.settling_s,
                  c.predicted.settling_s, c.measured.rest_peak_to_peak_m * 1e6, c.predicted.plant.c_str());
      cases.push_back(c);
    }
  }
  return cases;
}

std::string where(const Case& c) {
  return std::to_string(int(std::lround(c.measured.position_m * 1e3))) + " mm, " +
         std::to_string(int(c.measured.load_kg)) + " kg";
}

// The band, and the settling time as predicted.
void expect_band_and_predicted_settling(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    SCOPED_TRACE(where(c));
    EXPECT_LE(c.measured.overshoot_pct, kMaxOvershootPct);
    EXPECT_LE(c.measured.settling_s, kMaxSettlingS);
    EXPECT_NEAR(c.measured.settling_s, c.predicted.settling_s, kSettlingToleranceS);
  }
}

void expect_predicted_overshoot(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    SCOPED_TRACE(where(c));
    EXPECT_NEAR(c.measured.overshoot_pct, c.predicted.overshoot_pct, kOvershootTolerancePts);
  }
}

// The band's last line: the rod comes to rest (experiments.hpp, kOscillationLimitCounts).
void expect_rest(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    SCOPED_TRACE(where(c));
    EXPECT_FALSE(c.measured.oscillating) << c.measured.rest_peak_to_peak_counts << " counts peak to peak at rest";
  }
}

control::Tuning tuned_on(const control::GainGate& gate) {
  const std::optional<control::Tuning> t = control::tune_pi(gate, {}, control::PiGainsSi{85.0, 460.0});
  if (!t) throw std::runtime_error("no gains pass the gate on " + gate.plants.name);
  std::printf("tuned on %s: kp %.1f /m, ki %.1f /(m s); worst GM %.2f dB, PM %.2f deg, overshoot %.2f %%, "
              "settling %.3f s\n",
              gate.plants.name.c_str(), t->gains.kp, t->gains.ki,
              t->performance.verdict.worst_gain_margin.margins.gain_margin_db,
              t->performance.verdict.worst_phase_margin.margins.phase_margin_deg, t->performance.worst_overshoot_pct,
              t->performance.worst_settling_s);
  return *t;
}

// The baseline the tolerances come from: the paper's gains on the paper's rig, against Table A3.
TEST(TunedStep, ThePapersGainsOnThePapersRigStepAsTableA3Predicts) {
  const std::vector<Case> cases = nine_steps(sim::RigConfig{}, control::table_a3_plant_set(), {85.0, 460.0}, "paper's gains",
                                             analyze::kIntegralDeadBandM);
  expect_band_and_predicted_settling(cases);
  expect_predicted_overshoot(cases);
  expect_rest(cases);
}

const std::vector<Case>& table_a3_tuned_steps() {
  static const std::vector<Case> cases = [] {
    const control::GainGate gate{control::table_a3_plant_set(), {}};
    const control::Tuning t = tuned_on(gate);
    EXPECT_TRUE(gate.judge(t.gains).passed()) << gate.judge(t.gains).refusal;
    return nine_steps(sim::RigConfig{}, gate.plants, t.gains, "tuned on Table A3");
  }();
  return cases;
}

TEST(TunedStep, GainsTunedOnTableA3StepOnThePapersRigAsPredicted) {
  expect_band_and_predicted_settling(table_a3_tuned_steps());
  expect_predicted_overshoot(table_a3_tuned_steps());
}

// With the 10 µm integral dead band the tuned gains bring the rod to rest in all nine cases; with
// the paper's 5 µm they hunt without load (the header says by how much).
TEST(TunedStep, GainsTunedOnTableA3BringTheRodToRest) { expect_rest(table_a3_tuned_steps()); }

// And the band matters: with 5 µm the same gains hunt, so the test above pins the band, not luck.
TEST(TunedStep, GainsTunedOnTableA3HuntWithThePapersDeadBand) {
  const control::GainGate gate{control::table_a3_plant_set(), {}};
  const control::Tuning t = tuned_on(gate);
  analyze::Setup setup;
  setup.pi.kp = t.gains.kp;
  setup.pi.ki = t.gains.ki;
  setup.pi.integral_dead_band_m = analyze::kIntegralDeadBandM;
  const StepMetrics m = analyze::run_step(0.150, 0.0, setup);
  std::printf("tuned gains, 5 µm dead band, 150 mm 0 kg: rest p-p %.0f µm\n", m.rest_peak_to_peak_m * 1e6);
  EXPECT_TRUE(m.oscillating);
}

// The larger rig of test_identify.cpp and test_identify_set.cpp.
sim::RigConfig variant_rig() {
  sim::RigConfig rig;
  rig.cylinder.geometry = {.stroke_m = 0.304, .bore_m = 0.032, .rod_m = 0.018, .dead_length_m = 0.040};
  rig.supply = {.supply_pressure_pa = 40e5, .pump_flow_m3_per_s = 8.0 / 60000};
  rig.cylinder.static_friction_n = rig.cylinder.coulomb_friction_n = 4.0;
  return rig;
}

// One identification run per step case (12 s each, the identification's minimum is 10 s), read
// back through the CSV path of a recorded run, and the set `identify --set` makes of them.
control::PlantSet identified_set(const sim::RigConfig& rig) {
  std::vector<control::identification::NamedRun> runs;
  std::uint64_t seed = 70;
  for (double position : analyze::kStepPositionsM)
    for (double load : analyze::kLoadsKg) {
      test::ExcitationRun run{.position_m = position, .load_kg = load, .duration_s = 12.0};
      run.excitation.seed = ++seed;
      std::istringstream csv(test::excitation_csv(rig, run));
      runs.push_back({std::to_string(int(std::lround(position * 1e3))) + "mm@" + std::to_string(int(load)) + "kg",
                      load, analyze::read_telemetry_run(csv)});
    }
  const control::identification::SupplyRating rating{.supply_pressure_pa = rig.supply.supply_pressure_pa,
                                                     .pump_flow_m3_per_s = rig.supply.pump_flow_m3_per_s};
  return control::identification::identify_set(runs, test::identify_options_for(rig), rating).set;
}

struct VariantChain {
  control::GainGate gate;
  control::Tuning tuned;
  std::vector<Case> steps;
};

// identify → gate → tune → step on the variant, once for the tests below.
const VariantChain& variant_chain() {
  static const VariantChain chain = [] {
    const sim::RigConfig rig = variant_rig();
    control::GainGate gate{control::gate_plant_set(identified_set(rig), "the 32 mm variant's identified set"), {}};
    for (const control::IdentifiedPlant& p : gate.plants.plants)
      std::printf("  identified %-14s b0 %6.0f b1 %6.1f k01 %5.1f mm/s\n", control::plant_name(p).c_str(), p.b0, p.b1,
                  p.k01);
    const control::Tuning t = tuned_on(gate);
    std::vector<Case> steps = nine_steps(rig, gate.plants, t.gains, "tuned on the variant");
    return VariantChain{std::move(gate), t, std::move(steps)};
  }();
  return chain;
}

TEST(TunedStep, GainsTunedOnAnIdentifiedVariantPassItsGateAndRefusedOnesAreUnstableOnIt) {
  const VariantChain& chain = variant_chain();
  const control::GainGate& gate = chain.gate;
  ASSERT_EQ(gate.plants.plants.size(), 9u);
  const control::GateVerdict accepted = gate.judge(chain.tuned.gains);
  EXPECT_TRUE(accepted.passed()) << accepted.refusal;

  // Twice the gain at which a P loop goes unstable on the plant nearest to it (Routh on eq 41:
  // n·Kp < b0·b1, Kp < b1/k01 per mm); the integral only takes phase away, so with the tuned Ki
  // the loop is unstable on every plant of the set.
  double p_limit_per_m = 0.0;
  for (const control::IdentifiedPlant& p : gate.plants.plants) p_limit_per_m = std::max(p_limit_per_m, p.b1 / p.k01 * 1e3);
  const control::PiGainsSi unstable{.kp = 2.0 * p_limit_per_m, .ki = chain.tuned.gains.ki};
  const control::GateVerdict refused = gate.judge(unstable);
  EXPECT_FALSE(refused.passed());
  EXPECT_EQ(refused.unstable_plants, gate.plants.plants.size()) << refused.refusal;
  EXPECT_NE(refused.refusal.find("unstable"), std::string::npos) << refused.refusal;
  // And the rig agrees: the rod does not come to rest.
  analyze::Setup setup;
  setup.rig = variant_rig();
  setup.pi.kp = unstable.kp;
  setup.pi.ki = unstable.ki;
  const StepMetrics wild = analyze::run_step(0.150, 3.0, setup);
  std::printf("refused kp %.0f /m, ki %.0f /(m s) on the variant at 150 mm, 3 kg: rest p-p %.0f µm, settling %.2f s\n",
              unstable.kp, unstable.ki, wild.rest_peak_to_peak_m * 1e6, wild.settling_s);
  EXPECT_TRUE(wild.oscillating);
}

TEST(TunedStep, GainsTunedOnAnIdentifiedVariantStepOnItWithinTheBandAndSettleAsPredicted) {
  expect_band_and_predicted_settling(variant_chain().steps);
}

// On the variant the tuned kp of 111 /m asks the 10 mm step for an opening of 1.11; the PI clamps it
// at 1 and the rig overshoots 4.8–5.9 points less than the identified set predicts (12.8–15.1 %
// against 17.8–21.0 %), while it settles within 0.013 s of the prediction. The identification is
// not the cause (the identified plants are within 2 % of the rig's own linearization): the linear
// prediction knows no clamp. It is an upper bound here, and exact on the step below.
TEST(TunedStep, GainsTunedOnAnIdentifiedVariantOvershootNoMoreThanPredictedWhenTheValveSaturates) {
  for (const Case& c : variant_chain().steps) {
    SCOPED_TRACE(where(c));
    EXPECT_LE(c.measured.overshoot_pct, c.predicted.overshoot_pct + kOvershootTolerancePts);
  }
}

// The same gains on a step that keeps the opening within 0.9 (kp·step), at the nine working points:
// there the measured overshoot is what the identified set predicts, within the same tolerance.
TEST(TunedStep, GainsTunedOnAnIdentifiedVariantOvershootAsPredictedOnAStepThatDoesNotSaturateTheValve) {
  const VariantChain& chain = variant_chain();
  const double step_m = 0.9 / chain.tuned.gains.kp;
  std::printf("tuned on the variant, a %.2f mm step:\n", step_m * 1e3);
  for (double position : analyze::kStepPositionsM) {
    for (double load : analyze::kLoadsKg) {
      analyze::Setup setup;
      setup.rig = variant_rig();
      setup.pi.kp = chain.tuned.gains.kp;
      setup.pi.ki = chain.tuned.gains.ki;
      const StepMetrics m = analyze::run_step(position, load, setup, step_m);
      const StepPrediction p = analyze::predict_step(chain.gate.plants, position, load, chain.tuned.gains);
      std::printf("  %3.0f mm %1.0f kg  overshoot %5.2f %% (predicted %5.2f %%)  settling %.3f s (predicted %.3f s)\n",
                  position * 1e3, load, m.overshoot_pct, p.overshoot_pct, m.settling_s, p.settling_s);
      SCOPED_TRACE(testing::Message() << position * 1e3 << " mm, " << load << " kg");
      EXPECT_NEAR(m.overshoot_pct, p.overshoot_pct, kOvershootTolerancePts);
      EXPECT_NEAR(m.settling_s, p.settling_s, kSettlingToleranceS);
    }
  }
}

// With the 10 µm integral dead band, as on the paper's rig.
TEST(TunedStep, GainsTunedOnAnIdentifiedVariantBringTheRodToRest) { expect_rest(variant_chain().steps); }

}  // namespace
}  // namespace hsa
