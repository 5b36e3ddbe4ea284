#include "control/identification/nominal_plant.hpp"

#include <stdexcept>

#include "control/identification/closed_loop_model.hpp"

namespace hsa::control::identification {

NominalChoice choose_nominal(const std::vector<PlantEstimate>& candidates, const std::vector<RunRecord>& runs) {
  if (candidates.empty() || runs.empty()) throw std::invalid_argument("nominal plant: no candidate or no run");
  for (const RunRecord& run : runs) {
    if (run.setpoint_m == nullptr || run.position_m == nullptr || run.setpoint_m->size() != run.position_m->size() ||
        run.position_m->empty())
      throw std::invalid_argument("nominal plant: a run's setpoint and position are missing or differ in length");
  }
  NominalChoice choice;
  choice.fits.assign(candidates.size(), std::vector<double>(runs.size(), 0.0));
  choice.scores.assign(candidates.size(), 0.0);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = 0; j < runs.size(); ++j) {
      PlantEstimate plant = candidates[i];
      plant.leak_speed_mm_per_s = runs[j].leak_speed_mm_per_s;
      const std::vector<double> simulated = simulate_closed_loop(plant, runs[j].kp_per_m, *runs[j].setpoint_m,
                                                                 runs[j].position_m->front(), runs[j].period_s);
      choice.fits[i][j] = fit_index(*runs[j].position_m, simulated);
      choice.scores[i] += choice.fits[i][j];
    }
    if (choice.scores[i] > choice.scores[choice.index]) choice.index = i;
  }
  return choice;
}

}  // namespace hsa::control::identification
