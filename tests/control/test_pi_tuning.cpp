// The PI tuner over a plant set: its result meets the margins it was given on every plant, is at
// least as good as the paper's design on Table A3 under the paper's own margins, and nothing in
// the search box beats it by much.
#include "control/pi_tuning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace hsa::control {
namespace {

const PiGainsSi kPaperGains{85.0, 460.0};  // 0.085 per mm, 0.46 per mm·s (Puglisi et al. 2015)

std::vector<CylinderPlant> table_a3() {
  std::vector<CylinderPlant> plants;
  for (const auto& row : kTableA3) plants.push_back(row.plant());
  return plants;
}

// The paper's design judged on its own table: the margins it had become the tuner's minimum.
TuningLimits paper_margins() {
  const SetPerformance paper = evaluate_on_set(table_a3(), kPaperGains, TuningLimits{});
  return {.min_gain_margin_db = paper.worst_gain_margin_db, .min_phase_margin_deg = paper.worst_phase_margin_deg};
}

TEST(PiTuning, ThePapersGainsOnTableA3) {
  const SetPerformance p = evaluate_on_set(table_a3(), kPaperGains, TuningLimits{});
  std::printf("paper's gains on Table A3: GM %.2f dB (plant %zu), PM %.2f deg (plant %zu), settling %.3f s, "
              "overshoot %.1f %%, crossover >= %.2f rad/s\n",
              p.worst_gain_margin_db, p.worst_gain_margin_plant, p.worst_phase_margin_deg, p.worst_phase_margin_plant,
              p.worst_settling_s, p.worst_overshoot_pct, p.min_crossover_rad_s);
  EXPECT_TRUE(p.stable);
  // The worst of each figure is the worst of the per-plant analyses.
  double gm = 1e9, settling = 0.0;
  for (const auto& row : kTableA3) {
    gm = std::min(gm, stability_margins(row.plant(), kPaperGains).gain_margin_db);
    settling = std::max(settling, step_metrics(row.plant(), kPaperGains).settling_s);
  }
  EXPECT_EQ(p.worst_gain_margin_db, gm);
  EXPECT_EQ(p.worst_settling_s, settling);
}

// Found while writing this test: under the margins the paper's design itself has, its gains are
// where both margins bind, and a search from the grid alone ends 0.4 ms slower than them. Started
// from the running gains, as `hsa-analyze tune` is, it never returns worse.
TEST(PiTuning, OnTableA3WithThePapersMarginsItSettlesAtLeastAsFastAsThePaper) {
  const TuningLimits limits = paper_margins();
  const auto tuned = tune_pi(table_a3(), limits, kPaperGains);
  ASSERT_TRUE(tuned.has_value());
  const SetPerformance& t = tuned->performance;
  const SetPerformance paper = evaluate_on_set(table_a3(), kPaperGains, limits);
  std::printf("tuned: kp %.2f /m, ki %.2f /(m s) (%.4f /mm, %.4f /(mm s)); GM %.2f dB, PM %.2f deg, "
              "settling %.3f s (paper %.3f s), recovery %.3f s (paper %.3f s), overshoot %.1f %% (paper %.1f %%), "
              "crossover >= %.2f rad/s (paper %.2f); %d candidates\n",
              tuned->gains.kp, tuned->gains.ki, tuned->gains.kp * 1e-3, tuned->gains.ki * 1e-3,
              t.worst_gain_margin_db, t.worst_phase_margin_deg, t.worst_settling_s, paper.worst_settling_s,
              t.worst_recovery_s, paper.worst_recovery_s,
              t.worst_overshoot_pct, paper.worst_overshoot_pct, t.min_crossover_rad_s, paper.min_crossover_rad_s,
              tuned->candidates);
  EXPECT_TRUE(t.feasible);
  EXPECT_GE(t.worst_gain_margin_db, limits.min_gain_margin_db);
  EXPECT_GE(t.worst_phase_margin_deg, limits.min_phase_margin_deg);
  EXPECT_LE(std::max(t.worst_settling_s, t.worst_recovery_s), std::max(paper.worst_settling_s, paper.worst_recovery_s));
}

// No gains on a fine grid of the box, meeting the same margins, settle faster than the tuner's
// by more than 2 %: the search did not stop in a poor corner.
TEST(PiTuning, NothingOnAFineGridOfTheBoxIsClearlyBetter) {
  const TuningLimits limits = paper_margins();
  const std::vector<CylinderPlant> plants = table_a3();
  const auto tuned = tune_pi(plants, limits);
  ASSERT_TRUE(tuned.has_value());
  double best = 1e9;
  // Offset from the tuner's own grid (cell centres), and finer.
  for (int i = 0; i < 48; ++i) {
    for (int j = 0; j < 24; ++j) {
      const double kp = limits.kp_min * std::pow(limits.kp_max / limits.kp_min, (i + 0.5) / 48);
      const double corner = limits.corner_min * std::pow(limits.corner_max / limits.corner_min, (j + 0.5) / 24);
      const SetPerformance p = evaluate_on_set(plants, {kp, kp * corner}, limits, kSearchStepSamples);
      if (p.feasible) best = std::min(best, std::max(p.worst_settling_s, p.worst_recovery_s));
    }
  }
  const SetPerformance& t = tuned->performance;
  EXPECT_GE(best, std::max(t.worst_settling_s, t.worst_recovery_s) * 0.98);
}

TEST(PiTuning, TighterMarginsGiveSlowerGainsThatStillMeetThem) {
  const std::vector<CylinderPlant> plants = table_a3();
  TuningLimits limits = paper_margins();
  const auto loose = tune_pi(plants, limits);
  limits.min_phase_margin_deg += 10.0;
  limits.min_gain_margin_db += 4.0;
  const auto tight = tune_pi(plants, limits);
  ASSERT_TRUE(loose && tight);
  EXPECT_GE(tight->performance.worst_phase_margin_deg, limits.min_phase_margin_deg);
  EXPECT_GE(tight->performance.worst_gain_margin_db, limits.min_gain_margin_db);
  const auto time = [](const SetPerformance& p) { return std::max(p.worst_settling_s, p.worst_recovery_s); };
  EXPECT_GT(time(tight->performance), time(loose->performance));
}

TEST(PiTuning, MarginsNoGainsCanMeetGiveNothing) {
  // No PI gives 80 dB of gain margin with its crossover inside the box.
  const TuningLimits impossible{.min_gain_margin_db = 80.0, .min_phase_margin_deg = 60.0};
  EXPECT_FALSE(tune_pi(table_a3(), impossible).has_value());
}

TEST(PiTuning, RefusesAnEmptySetOrBox) {
  EXPECT_THROW((void)tune_pi({}, TuningLimits{}), std::invalid_argument);
  TuningLimits empty_box;
  empty_box.kp_max = empty_box.kp_min;
  EXPECT_THROW((void)tune_pi(table_a3(), empty_box), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
