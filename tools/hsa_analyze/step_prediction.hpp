// What the linear models predict for a step experiment (experiments.hpp, run_step): the closed
// loop of the PI on the plant of a set (Table A3, or a set `hsa-analyze identify --set` wrote)
// nearest the step's working point, as `hsa-analyze tune` predicts it over the whole set
// (control/loop_analysis.hpp; Puglisi et al. 2015, eq 41 closed with K(s) = Kp + Ki/s).
//
// Nearest: the plant whose load is nearest the case's, and among those the one whose position is
// nearest (ties: the first in the set's order). The load comes first because it moves the plant
// more than the position does: Table A3's b0 drops by a third from 0 to 6 kg, and changes by less
// than a fifth between neighbouring positions 30 mm apart.
#pragma once

#include <cstddef>
#include <string>

#include "control/gain_gate.hpp"
#include "control/loop_analysis.hpp"

namespace hsa::analyze {

// Index into set.plants. Throws std::invalid_argument for an empty set.
std::size_t nearest_plant(const control::GatePlantSet& set, double position_m, double load_kg);

struct StepPrediction {
  std::string plant;           // as the gate names it: "6 kg / 150 mm"
  double overshoot_pct = 0.0;  // NaN when the loop is unstable on that plant
  double settling_s = 0.0;     // 2 % band; NaN when unstable
};

// Throws std::invalid_argument as nearest_plant and control::step_metrics do.
StepPrediction predict_step(const control::GatePlantSet& set, double position_m, double load_kg,
                            const control::PiGainsSi& gains);

}  // namespace hsa::analyze
