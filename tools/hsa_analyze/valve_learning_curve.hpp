// How the learning law's triangle residual falls with the periods it has had to learn
// (docs/valve-loop.md, "learning"): the experiment's triangle, scored exactly as
// run_valve_triangle scores it (eq 9 over its 4 scored periods), run again with 0, 1, … extra
// settle periods before the score.
#pragma once

#include <vector>

#include "tools/hsa_analyze/valve_experiments.hpp"

namespace hsa::analyze {

// Entry p: the 70 % triangle at 10 Hz scored after 2 + p periods (p = 0 … periods).
std::vector<ValveTriangleMetrics> valve_learning_curve(const control::ValveLawParams& law,
                                                       const sim::ProportionalValveParameters& plant, int periods);

}  // namespace hsa::analyze
