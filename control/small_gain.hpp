// Robust stability of the PI cylinder loop under multiplicative uncertainty (Puglisi et al. 2015,
// section 4.3.2, eqs 53-61): the identified plants are taken as the family
//
//   Π = { P0·(1 + W1·Δ) : Δ ∈ RH∞, ‖Δ‖∞ < 1 }                    (eqs 53, 54)
//
// around the nominal plant P0 (eq 52), and a controller K that stabilizes P0 stabilizes the whole
// family if and only if ‖W1·T0‖∞ ≤ 1, with T0 = P0·K / (1 + P0·K) (Theorem 1 and eq 61).
//
// The norm is the peak of |W1(jω)·T0(jω)| over ω, taken on a logarithmic grid and refined by a
// golden-section search around the largest sample. It means something only when K stabilizes P0,
// so the closed-loop poles of P0 are checked first (`nominal_stable`).
//
// W1 as eq 54 prints it has 2.159e6 for its s coefficient; with it ‖W1·T0‖∞ is about 61, not the
// 0.8523 of eq 61, and |W1| exceeds the plants' error of Fig. 16 a hundredfold. kW1 takes 2.159e4:
// with it ‖W1·T0‖∞ is 0.853 for the gains whose poles eq 60 prints (Kp = 0.085, Ki ≈ 0.238 per
// mm), the printed 0.8523 to 0.1 %, and |W1(jω)| bounds the relative error |Pi − P0|/|P0| of all
// 33 plants of Table A3 over the paper's range ω ∈ [1e-2, 1e3] rad/s (tests/control pin both).
#pragma once

#include <array>

#include "control/loop_analysis.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {

// A proper rational weight of order 3, coefficients in descending powers of s.
struct CubicWeight {
  std::array<double, 4> num{};
  std::array<double, 4> den{};
};

// W1 of eq 54 with the s coefficient of its numerator corrected (see above).
inline constexpr CubicWeight kW1{{1.759, 724.9, 2.159e4, 2.406e5}, {1.0, 313.9, 2.65e4, 6.275e5}};

// The multiplicative uncertainty model of a plant set: the nominal plant and the weight that
// bounds the other plants' relative error.
struct UncertaintyModel {
  CylinderPlant nominal;
  CubicWeight w1;
};

// The model of Puglisi et al. (2015) for Table A3: P0 of eq 52 and kW1.
inline constexpr UncertaintyModel kTableA3Uncertainty{kNominalPlant, kW1};

struct SmallGainResult {
  bool nominal_stable = false;  // K stabilizes the nominal plant; otherwise the norm is NaN
  double norm = 0.0;            // ‖W1·T0‖∞
  double peak_rad_s = 0.0;      // where it is reached
};

// Throws std::invalid_argument for gains or a plant loop_analysis.hpp refuses.
SmallGainResult weighted_complementary_sensitivity(const UncertaintyModel& model, const PiGainsSi& gains);

// |W(jω)|.
double weight_magnitude(const CubicWeight& w, double omega_rad_s);

}  // namespace hsa::control
