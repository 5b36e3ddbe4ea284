// The gain gate's closed-form margins against loop_analysis's frequency sweep, on every plant of
// Table A3 and gains from P control to unstable: the same margins and crossovers.
#include "control/closed_form_margins.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace hsa::control {
namespace {

TEST(ClosedFormMargins, AgreeWithTheSweepOnEveryPlantOfTableA3) {
  const PiGainsSi cases[] = {{85.0, 460.0}, {400.0, 460.0}, {120.0, 460.0}, {70.0, 400.0}, {1000.0, 0.0},
                             {40.0, 900.0}, {10.0, 0.0},    {5.0, 2000.0},  {2000.0, 5e4}};
  for (const PiGainsSi& g : cases) {
    for (const IdentifiedPlant& row : kTableA3) {
      SCOPED_TRACE(std::to_string(row.position_mm) + " mm, " + std::to_string(row.load_kg) + " kg, kp " +
                   std::to_string(g.kp) + ", ki " + std::to_string(g.ki));
      const StabilityMargins sweep = stability_margins(row.plant(), g);
      const StabilityMargins closed = closed_form_margins(row.plant(), g);
      if (std::isinf(sweep.gain_margin_db)) {
        EXPECT_TRUE(std::isinf(closed.gain_margin_db));
      } else {
        EXPECT_NEAR(closed.gain_margin_db, sweep.gain_margin_db, 1e-6);
        EXPECT_NEAR(closed.phase_crossover_rad_s, sweep.phase_crossover_rad_s, 1e-6 * sweep.phase_crossover_rad_s);
      }
      ASSERT_FALSE(std::isnan(sweep.phase_margin_deg));
      EXPECT_NEAR(closed.phase_margin_deg, sweep.phase_margin_deg, 1e-6);
      EXPECT_NEAR(closed.crossover_rad_s, sweep.crossover_rad_s, 1e-6 * sweep.crossover_rad_s);
    }
  }
}

TEST(ClosedFormMargins, RefusesWhatTheSweepRefuses) {
  EXPECT_THROW(closed_form_margins(kNominalPlant, {0.0, 460.0}), std::invalid_argument);
  EXPECT_THROW(closed_form_margins(kNominalPlant, {85.0, -1.0}), std::invalid_argument);
  EXPECT_THROW(closed_form_margins({1.0, 0.0, 1.0}, {85.0, 460.0}), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
