#include "tools/hsa_analyze/step_prediction.hpp"

#include <cmath>
#include <stdexcept>

namespace hsa::analyze {

std::size_t nearest_plant(const control::GatePlantSet& set, double position_m, double load_kg) {
  if (set.plants.empty()) throw std::invalid_argument("nearest_plant: the plant set '" + set.name + "' is empty");
  std::size_t best = 0;
  const auto distance = [&](std::size_t i) {
    const control::IdentifiedPlant& p = set.plants[i];
    return std::pair{std::abs(p.load_kg - load_kg), std::abs(p.position_m() - position_m)};
  };
  for (std::size_t i = 1; i < set.plants.size(); ++i)
    if (distance(i) < distance(best)) best = i;
  return best;
}

StepPrediction predict_step(const control::GatePlantSet& set, double position_m, double load_kg,
                            const control::PiGainsSi& gains) {
  const control::IdentifiedPlant& p = set.plants[nearest_plant(set, position_m, load_kg)];
  const control::StepMetrics m = control::step_metrics(p.plant(), gains);
  return {control::plant_name(p), m.overshoot_pct, m.settling_s};
}

}  // namespace hsa::analyze
