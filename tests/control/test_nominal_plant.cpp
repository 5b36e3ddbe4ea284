// Eq 49 of Puglisi et al. (2015) on a case whose answer is known: runs made by the closed-loop
// model itself (closed_loop_model.hpp) from plants whose b0 spreads evenly around a middle one.
// Each run is explained exactly by its own plant; the middle plant is the nearest to all the
// others, so it has the best summed fit, and a far outlier among the candidates loses.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "control/identification/closed_loop_model.hpp"
#include "control/identification/nominal_plant.hpp"
#include "control/excitation_sequence.hpp"

namespace hsa::control::identification {
namespace {

PlantEstimate plant(double b0) {
  PlantEstimate p;
  p.b0 = {b0, 0.0};
  p.b1 = {100.0, 0.0};
  p.k01 = {240.0, 0.0};
  p.k01_retracting = {210.0, 0.0};
  p.delay_s = 0.5e-3;
  return p;
}

TEST(NominalPlant, PicksThePlantInTheMiddleOfTheRuns) {
  const std::vector<PlantEstimate> candidates{plant(8000), plant(9500), plant(11000), plant(12500), plant(14000),
                                              plant(30000)};
  ExcitationParams params{.amplitude = 1e-3, .switching_time_s = 0.3, .levels = 5, .seed = 7};
  params.sample_period_s = 1e-3;
  ExcitationSequence excitation(params);
  std::vector<double> setpoint(10000);
  for (double& r : setpoint) r = 0.15 + excitation.next();
  std::vector<std::vector<double>> positions;
  std::vector<RunRecord> runs;
  for (std::size_t j = 0; j < 5; ++j)
    positions.push_back(simulate_closed_loop(candidates[j], 200.0, setpoint, 0.15, 1e-3));
  for (const auto& y : positions) runs.push_back({&setpoint, &y, 1e-3, 200.0, 0.0});
  const NominalChoice c = choose_nominal(candidates, runs);
  for (std::size_t j = 0; j < 5; ++j) EXPECT_NEAR(c.fits[j][j], 1.0, 1e-12);
  EXPECT_EQ(c.index, 2u);
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (i != 2) {
      EXPECT_LT(c.scores[i], c.scores[2]) << i;
    }
  EXPECT_LT(c.scores[5], c.scores[0]);  // the outlier is the worst
}

TEST(NominalPlant, RefusesNoCandidateOrARunOfMismatchedLength) {
  std::vector<double> r(10, 0.0), y(9, 0.0);
  EXPECT_THROW((void)choose_nominal({}, {{&r, &r, 1e-3, 200.0, 0.0}}), std::invalid_argument);
  EXPECT_THROW((void)choose_nominal({plant(1e4)}, {{&r, &y, 1e-3, 200.0, 0.0}}), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control::identification
