// The turbulent orifice equation Q = c·sign(Δp)·√|Δp| (Puglisi et al. 2015, section 2: "the orifice
// equation for the servo-valve"), with a laminar region below `laminar_dp` so that the flow has a
// finite slope at Δp = 0. Without it the slope is infinite at zero pressure drop and a fixed-step
// integrator chatters whenever a chamber reaches supply or tank pressure.
#pragma once

#include <cmath>

namespace hsa::sim {

inline constexpr double kOrificeLaminarDeltaP = 0.2e5;  // 0.2 bar

[[nodiscard]] inline double orifice_flow(double conductance, double delta_p,
                                         double laminar_dp = kOrificeLaminarDeltaP) {
  const double magnitude = std::abs(delta_p);
  if (magnitude >= laminar_dp) return std::copysign(conductance * std::sqrt(magnitude), delta_p);
  // Linear through zero, meeting the turbulent branch at ±laminar_dp.
  return conductance * delta_p / std::sqrt(laminar_dp);
}

}  // namespace hsa::sim
