// The nominal plant of a set identified at several working points, by the criterion of Puglisi et
// al. (2015), section 4.1.1, eqs 49–50: the identified plant P_i that best explains every run,
//
//   i* = argmax_i  Σ_j F(P_i, run j),     F = 1 − ‖y_j − y_s,ij‖ / ‖y_j − ȳ_j‖,
//
// where y_s,ij is P_i's output on run j's input. Eq 50 as printed is garbled; F is meant to be the
// fit index of eq 39, and that is what is used here. The runs are closed-loop under a P controller
// (section 3.1.1), so run j's input is its setpoint and P_i is simulated in run j's loop, with run
// j's P gain, as G_cl of eq 31 (closed_loop_model.hpp). Candidate i brings its linear plant (b0,
// b1, k01⁺, k01⁻, τ); the closed valve's leak speed v₀ is run j's own, because it is set by the load
// that holds run j's chambers, as F_e is, and is no part of the transfer function the criterion
// compares.
#pragma once

#include <cstddef>
#include <vector>

#include "control/identification/plant_estimate.hpp"

namespace hsa::control::identification {

// What eq 49 needs of one run: its input and output, its P gain and its working point's leak speed.
struct RunRecord {
  const std::vector<double>* setpoint_m = nullptr;
  const std::vector<double>* position_m = nullptr;
  double period_s = 1e-3;
  double kp_per_m = 0.0;
  double leak_speed_mm_per_s = 0.0;
};

struct NominalChoice {
  std::size_t index = 0;             // i*
  std::vector<double> scores;        // Σ_j F(P_i, run j), one per candidate
  std::vector<std::vector<double>> fits;  // fits[i][j] = F(P_i, run j)
};

// Throws std::invalid_argument when there is no candidate or no run, or a run's records are
// missing or differ in length.
[[nodiscard]] NominalChoice choose_nominal(const std::vector<PlantEstimate>& candidates,
                                           const std::vector<RunRecord>& runs);

}  // namespace hsa::control::identification
