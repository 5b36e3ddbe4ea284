// The gain and phase margins of the PI cylinder loop (loop_analysis.hpp) in closed form, for the
// gain gate, which judges 33 plants on every gain change: the same numbers as
// stability_margins(), without its frequency sweep (about 1000 times faster).
//
// With K = Kp + Ki/s and P = g / (s·(s² + b1·s + b0)) (Puglisi et al. 2015, eqs 38 and 41):
// - phase crossover: arg L(jω) = −π where atan2(Kp·ω, Ki) = atan2(b1·ω, b0 − ω²), both angles in
//   (0, π): the vectors (Ki, Kp·ω) and (b0 − ω², b1·ω) are parallel, so
//     ω² = b0 − Ki·b1/Kp   (one crossover when positive; none otherwise, and then the phase stays
//                           below −π at every frequency and the gain margin is +inf, as in
//                           stability_margins);
// - gain crossover: |L(jω)| = 1 where, with x = ω²,
//     x⁴ + (b1² − 2·b0)·x³ + b0²·x² − g²·Kp²·x − g²·Ki² = 0,
//   whose positive real roots are found as eigenvalues of its companion matrix and polished by
//   Newton's method; the phase margin is the smallest over them.
#pragma once

#include "control/loop_analysis.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {

// Throws std::invalid_argument as stability_margins() does.
StabilityMargins closed_form_margins(const CylinderPlant& plant, const PiGainsSi& gains);

}  // namespace hsa::control
