// The robustness gate of the PI gains (control/gain_gate.hpp): the paper's design passes on Table
// A3 with the defaults just below its own margins, and each condition refuses on its own with the
// worst plant named and its number, whatever the order of the plants.
#include "control/gain_gate.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace hsa::control {
namespace {

using ::testing::HasSubstr;

const PiGainsSi kPaperGains{85.0, 460.0};  // Puglisi et al. 2015, section 4.2: 0.085/mm, 0.46/(mm s)

TEST(GainGate, TableA3SetHasTheNominalPlantOfEquation51) {
  const GatePlantSet set = table_a3_plant_set();
  ASSERT_EQ(set.plants.size(), 33u);
  EXPECT_EQ(set.plants[set.nominal].position_mm, 120);
  EXPECT_EQ(set.plants[set.nominal].load_kg, 6);
  ASSERT_TRUE(set.uncertainty.has_value());
}

// The defaults are just below the paper's worst margins on Table A3: its gains pass, by less than
// one unit of each margin. (Recomputed independently of loop_analysis: 11.90 dB at 6 kg / 290 mm,
// 60.98° at 6 kg / 150 mm.)
TEST(GainGate, PaperGainsPassOnTableA3JustAboveTheDefaults) {
  const GateVerdict v = judge_gains(table_a3_plant_set(), {}, kPaperGains);
  EXPECT_TRUE(v.passed()) << v.refusal;
  EXPECT_EQ(v.unstable_plants, 0u);
  EXPECT_EQ(plant_name(v.worst_gain_margin.plant), "6 kg / 290 mm");
  EXPECT_EQ(plant_name(v.worst_phase_margin.plant), "6 kg / 150 mm");
  const double gm = v.worst_gain_margin.margins.gain_margin_db;
  const double pm = v.worst_phase_margin.margins.phase_margin_deg;
  EXPECT_GT(gm, kDefaultMinGainMarginDb);
  EXPECT_LT(gm - kDefaultMinGainMarginDb, 1.0);
  EXPECT_GT(pm, kDefaultMinPhaseMarginDeg);
  EXPECT_LT(pm - kDefaultMinPhaseMarginDeg, 1.0);
  ASSERT_TRUE(v.small_gain.has_value());
  EXPECT_LT(v.small_gain->norm, 1.0);
  // The worst is the worst: no plant of the set has a smaller margin than the gate reports.
  for (const IdentifiedPlant& row : kTableA3) {
    const StabilityMargins m = stability_margins(row.plant(), kPaperGains);
    EXPECT_GE(m.gain_margin_db, gm - 1e-6) << plant_name(row);
    EXPECT_GE(m.phase_margin_deg, pm - 1e-6) << plant_name(row);
  }
}

// kp 400 (ki 460) closes an unstable loop on the heaviest, stiffest-gain plants: the refusal names
// the unstable plant with the smallest (most negative) gain margin, and that margin.
TEST(GainGate, UnstableGainsAreRefusedNamingTheWorstPlant) {
  const PiGainsSi gains{400.0, 460.0};
  const GateVerdict v = judge_gains(table_a3_plant_set(), {}, gains);
  ASSERT_FALSE(v.passed());
  EXPECT_GT(v.unstable_plants, 0u);
  EXPECT_THAT(v.refusal, ::testing::StartsWith("unstable on plant 6 kg / 290 mm (GM -1.19 dB), "));
  EXPECT_THAT(v.refusal, HasSubstr(std::to_string(v.unstable_plants) + " of the 33 plants of Table A3"));
  // Cross-checked on the poles: the named plant is unstable, and the count is right.
  std::size_t unstable = 0;
  for (const IdentifiedPlant& row : kTableA3) {
    const bool stable = closed_loop_poles(row.plant(), gains).front().real() < 0.0;
    unstable += stable ? 0 : 1;
    if (row.position_mm == 290 && row.load_kg == 6) {
      EXPECT_FALSE(stable);
    }
  }
  EXPECT_EQ(v.unstable_plants, unstable);
}

// kp 120: stable on every plant, but its gain margin (9.04 dB at 6 kg / 290 mm) is under 11 dB.
TEST(GainGate, StableGainsUnderTheMinimumGainMarginAreRefusedWithTheMargin) {
  const GateVerdict v = judge_gains(table_a3_plant_set(), {}, {120.0, 460.0});
  EXPECT_EQ(v.unstable_plants, 0u);
  EXPECT_EQ(v.refusal, "gain margin 9.04 dB on plant 6 kg / 290 mm below the minimum 11 dB (min_gain_margin_db)");
  // With the minimum lowered below it, the gain margin no longer refuses them.
  const GateVerdict lowered = judge_gains(table_a3_plant_set(), {.min_gain_margin_db = 9.0}, {120.0, 460.0});
  EXPECT_THAT(lowered.refusal, ::testing::Not(HasSubstr("gain margin")));
}

// kp 70, ki 400: more gain margin than the paper's (13.6 dB), less phase (59.71° at 6 kg / 120 mm).
TEST(GainGate, StableGainsUnderTheMinimumPhaseMarginAreRefusedWithTheMargin) {
  const GateVerdict v = judge_gains(table_a3_plant_set(), {}, {70.0, 400.0});
  EXPECT_EQ(v.unstable_plants, 0u);
  EXPECT_GT(v.worst_gain_margin.margins.gain_margin_db, kDefaultMinGainMarginDb);
  EXPECT_EQ(v.refusal, "phase margin 59.71° on plant 6 kg / 120 mm below the minimum 60° (min_phase_margin_deg)");
  EXPECT_TRUE(judge_gains(table_a3_plant_set(), {.min_phase_margin_deg = 59.0}, {70.0, 400.0}).passed());
}

// kp 100 is stable with margins over zero on every plant, but fails ‖W1·T0‖∞ ≤ 1; a set without
// an uncertainty model (no W1) is judged on its margins alone and passes.
TEST(GainGate, SmallGainViolationIsRefused) {
  const MarginRequirements none{.min_gain_margin_db = 0.0, .min_phase_margin_deg = 0.0};
  const PiGainsSi gains{100.0, 460.0};
  const GateVerdict v = judge_gains(table_a3_plant_set(), none, gains);
  EXPECT_EQ(v.unstable_plants, 0u);
  ASSERT_TRUE(v.small_gain.has_value());
  EXPECT_GT(v.small_gain->norm, 1.0);
  EXPECT_THAT(v.refusal, ::testing::StartsWith("robust stability not shown: ||W1 T0||inf = 1.0"));
  EXPECT_THAT(v.refusal, HasSubstr("eq 61"));

  GatePlantSet margins_only = table_a3_plant_set();
  margins_only.uncertainty.reset();
  const GateVerdict m = judge_gains(margins_only, none, gains);
  EXPECT_TRUE(m.passed()) << m.refusal;
  EXPECT_FALSE(m.small_gain.has_value());
}

// The verdict, its text and the plants it names are the same in any order of the set, including
// between two plants with the same coefficients (a tie) at different working points.
TEST(GainGate, VerdictIsIndependentOfPlantOrder) {
  GatePlantSet base = table_a3_plant_set();
  IdentifiedPlant twin = base.plants[32];  // 6 kg / 290 mm, the smallest gain margin
  twin.position_mm = 300;
  base.plants.push_back(twin);
  std::mt19937 random(2015);
  for (const PiGainsSi gains : {kPaperGains, PiGainsSi{400.0, 460.0}, PiGainsSi{120.0, 460.0},
                                PiGainsSi{70.0, 400.0}, PiGainsSi{1000.0, 0.0}}) {
    const GateVerdict reference = judge_gains(base, {}, gains);
    for (int trial = 0; trial < 4; ++trial) {
      GatePlantSet shuffled = base;
      if (trial == 0) std::reverse(shuffled.plants.begin(), shuffled.plants.end());
      else std::shuffle(shuffled.plants.begin(), shuffled.plants.end(), random);
      const GateVerdict v = judge_gains(shuffled, {}, gains);
      EXPECT_EQ(v.refusal, reference.refusal) << gains.kp << ", " << gains.ki;
      EXPECT_EQ(v.unstable_plants, reference.unstable_plants);
      EXPECT_EQ(plant_name(v.worst_gain_margin.plant), plant_name(reference.worst_gain_margin.plant));
      EXPECT_EQ(plant_name(v.worst_phase_margin.plant), plant_name(reference.worst_phase_margin.plant));
    }
  }
  // The tie goes to the lower position whatever the order.
  EXPECT_EQ(plant_name(judge_gains(base, {}, kPaperGains).worst_gain_margin.plant), "6 kg / 290 mm");
}

TEST(GainGate, EmptySetAndBadGainsAreRefusedAsArguments) {
  GatePlantSet empty = table_a3_plant_set();
  empty.plants.clear();
  EXPECT_THROW(judge_gains(empty, {}, kPaperGains), std::invalid_argument);
  EXPECT_THROW(judge_gains(table_a3_plant_set(), {}, {0.0, 460.0}), std::invalid_argument);
  EXPECT_THROW(judge_gains(table_a3_plant_set(), {}, {85.0, NAN}), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
