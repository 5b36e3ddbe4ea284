// The simulated rig's small-signal plant against the paper's identified plants (Table A3).
// The rig is calibrated from Tables A1 and A2 only, so this is a check, not a restatement.
#include <gtest/gtest.h>

#include "sim/calibration.hpp"
#include "control/plant_table.hpp"
#include "sim/paper_tables.hpp"

namespace hsa::sim {
namespace {

TEST(Calibration, CoversAllThirtyThreeWorkingPoints) {
  const auto rows = calibration_table(CylinderParameters{}, SupplyParameters{}, control::kTableA3);
  ASSERT_EQ(rows.size(), paper::kWorkingPositions * paper::kLoads);
  EXPECT_DOUBLE_EQ(rows.front().position_m, 0.010);
  EXPECT_DOUBLE_EQ(rows.back().position_m, 0.290);
  EXPECT_DOUBLE_EQ(rows.back().load_kg, 6.0);
}

// The acceptance limit is 10 % on each coefficient.
TEST(Calibration, WorstDeviationFromTableA3IsWithinTenPercent) {
  const auto rows = calibration_table(CylinderParameters{}, SupplyParameters{}, control::kTableA3);
  for (const auto& r : rows) {
    SCOPED_TRACE(testing::Message() << "working point " << r.position_m * 1e3 << " mm, " << r.load_kg << " kg");
    EXPECT_LE(std::abs(r.b0_deviation()), 0.10) << "b0 " << r.b0 << " vs " << r.b0_table;
    EXPECT_LE(std::abs(r.b1_deviation()), 0.10) << "b1 " << r.b1 << " vs " << r.b1_table;
    EXPECT_LE(std::abs(r.k01_deviation()), 0.10) << "k01 " << r.k01 << " vs " << r.k01_table;
  }
  const CalibrationSummary worst = worst_deviation(rows);
  RecordProperty("worst_b0_percent", std::to_string(100 * worst.b0));
  RecordProperty("worst_b1_percent", std::to_string(100 * worst.b1));
  RecordProperty("worst_k01_percent", std::to_string(100 * worst.k01));
}

// Tables A1 and A2 reproduce A3 within 1 % through eqs 19–21 of Puglisi et al. (2015). The simulator adds its own
// departures from the paper's reduced model (two chambers, leakage, orifice at the hold point);
// this pins that those stay at the level of the tables' own rounding and a little more, so a
// regression in the model's equations shows here before it reaches the 10 % limit.
TEST(Calibration, DeviationsStayAtTheLevelOfTheTablesOwnConsistency) {
  const CalibrationSummary worst = worst_deviation(calibration_table(CylinderParameters{}, SupplyParameters{}, control::kTableA3));
  EXPECT_LT(worst.b0, 0.02);
  EXPECT_LT(worst.b1, 0.02);
  EXPECT_LT(worst.k01, 0.02);
}

// The check can fail: a valve that leaks like the paper's Kp read as a leak would (tens of L/min)
// adds the load-pressure relaxation twice, once as leak and once as the calibrated rod damping,
// and the damping b1 comes out far too high.
TEST(Calibration, DetectsAValveThatLeaksLikeTheIdentifiedKp) {
  CylinderParameters leaky;
  leaky.null_leakage_m3_per_s = 30.0 / 60000;
  const CalibrationSummary worst = worst_deviation(calibration_table(leaky, SupplyParameters{}, control::kTableA3));
  EXPECT_GT(worst.b1, 0.10);
}

}  // namespace
}  // namespace hsa::sim
