#include "control/plant_table.hpp"

#include <set>
#include <utility>

#include <gtest/gtest.h>

namespace hsa::control {
namespace {

TEST(PlantTable, HoldsElevenPositionsTimesThreeLoads) {
  std::set<std::pair<int, int>> points;
  std::set<int> positions;
  for (const IdentifiedPlant& row : kTableA3) {
    points.insert({row.position_mm, row.load_kg});
    positions.insert(row.position_mm);
    EXPECT_TRUE(row.load_kg == 0 || row.load_kg == 3 || row.load_kg == 6);
    // k01 (the no-load speed at full opening) lies in 224–294 mm/s in the paper's table.
    EXPECT_GE(row.k01, 224.0);
    EXPECT_LE(row.k01, 294.0);
  }
  EXPECT_EQ(points.size(), 33u);
  EXPECT_EQ(positions, (std::set<int>{10, 30, 60, 90, 120, 150, 180, 210, 240, 270, 290}));
}

TEST(PlantTable, FindsRowsBySiWorkingPoint) {
  const auto row = find_identified_plant(0.12, 6.0);
  ASSERT_TRUE(row.has_value());
  EXPECT_EQ(row->position_mm, 120);
  EXPECT_EQ(row->load_kg, 6);
  EXPECT_FALSE(find_identified_plant(0.5, 3.0).has_value());
  EXPECT_FALSE(find_identified_plant(0.12, 2.0).has_value());
}

// Eq 51: P0 is the plant identified at [6 kg, 120 mm]. Table A3 prints that row with integers:
// b1 = 90 and k01 = 224 agree with eq 52 (90.31, and 1.722e6/7692 = 223.87) to that rounding.
// b0 does not: the table has 7701, eq 52 has 7692, 9 units (0.12 %) apart, more than rounding.
// The analysis uses each as printed ("nominal" is eq 52, "0.12:6" the table row); the test pins
// the size of the discrepancy so that a transcription error would show.
TEST(PlantTable, NominalPlantIsTheRowAt120mm6kg) {
  const IdentifiedPlant row = *find_identified_plant(0.12, 6.0);
  EXPECT_NEAR(row.b1, kNominalPlant.b1, 0.5);
  EXPECT_NEAR(row.k01, kNominalPlant.gain / kNominalPlant.b0, 0.5);
  EXPECT_EQ(row.b0 - kNominalPlant.b0, 9.0);
}

}  // namespace
}  // namespace hsa::control
