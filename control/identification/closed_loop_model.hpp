// The identified plant (plant_estimate.hpp) closed with the run's proportional controller, simulated
// from the run's setpoint: the model's answer to the run, G_cl of Puglisi et al. (2015), eq 31,
// in discrete time at the loop's period as the loop ran it:
//
//   xv(k) = clamp(K·(r(k) − y_s(k)), −1, 1)
//   y_s: the plant's state sampled exactly with xv held over each period and delayed by τ
//        (sampled_lti.hpp), driven by k01·xv⁺ + k01⁻·xv⁻ + v₀.
//
// It starts at rest at the first measured position. The paper's fit
// index (eq 39) compares it with the measured position:
//
//   F = 1 − ‖y − y_s‖ / ‖y − ȳ‖                     (1 = perfect, 0 = no better than the mean)
#pragma once

#include <vector>

#include "control/identification/plant_estimate.hpp"

namespace hsa::control::identification {

// setpoint_m per period; kp_per_m: the P gain in valve opening per metre. Returns y_s in metres.
[[nodiscard]] std::vector<double> simulate_closed_loop(const PlantEstimate& plant, double kp_per_m,
                                                       const std::vector<double>& setpoint_m, double initial_position_m,
                                                       double period_s);

// Eq 39. Throws std::invalid_argument for vectors of different length or a constant y.
[[nodiscard]] double fit_index(const std::vector<double>& measured, const std::vector<double>& simulated);

}  // namespace hsa::control::identification
