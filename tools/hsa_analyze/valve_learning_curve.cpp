#include "tools/hsa_analyze/valve_learning_curve.hpp"

namespace hsa::analyze {

std::vector<ValveTriangleMetrics> valve_learning_curve(const control::ValveLawParams& law,
                                                       const sim::ProportionalValveParameters& plant, int periods) {
  std::vector<ValveTriangleMetrics> curve;
  control::ValveLawParams run = law;
  for (int p = 0; p <= periods; ++p) {
    run.learning_settle_periods = p;
    curve.push_back(run_valve_triangle(0.70, 10.0, run, plant));
  }
  return curve;
}

}  // namespace hsa::analyze
