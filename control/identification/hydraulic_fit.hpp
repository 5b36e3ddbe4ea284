// The valve and oil half of the plant of Puglisi et al. (2015): the load-pressure equation
// behind eqs 8–21, in the form the rig's pressures show it,
//
//   Ap·dP_L/dt = k_h·(k⁺·xv⁺(t − τ) + k⁻·xv⁻(t − τ) + v₀ − ẏ),     P_L = P_A − α·P_B,
//
// k_h the hydraulic stiffness (N/m), k± the rod speed per unit opening (mm/s, the paper's k01)
// for openings that extend (xv⁺ = max(xv, 0)) and retract (xv⁻ = min(xv, 0)), v₀ the speed the
// closed valve's leakage gives. Unlike the position alone, this equation has no friction in it:
// the seals' force acts on the rod, not on the oil. With m and σ from the force balance
// (motion_fit.hpp), eqs 19–21 give the paper's plant: b0 = k_h/m, b1 = σ/m, k01 = k⁺ (the
// paper's section 3.2.1 combines the two fits the same way, eqs 35–37).
//
// Why two gains: the servo-valve is closed-centre and the cylinder differential, so an opening
// that extends meters P→A and B→T across √(P_s − P_A) and √P_B, one that retracts A→T and P→B
// across √P_A and √(P_s − P_B). At the pressures that hold the load these differ (about 12 % at
// 0 kg on the paper's rig), and the linearization at the hold point has a kink at xv = 0. A single
// k01 fitted to a symmetric excitation lands between the two; the paper's tables (and the
// simulator's calibration) give the extending one.
//
// Method: continuous-time equation-error least squares with state-variable filters (Young 1981;
// Garnier et al. 2003). Every signal goes through the same filter F(s) = λ⁴/(s + λ)⁴, whose
// states are the filtered signal and its derivatives, exactly; F commutes with the equation, so
// the filtered signals obey it and it is linear in (k_h·k⁺, k_h·k⁻, k_h, k_h·v₀). The openings
// are sampled as the loop held them (zero-order hold); P_L and y as the smooth signals they are
// (first-order hold), or the half-period between the two reads would land in τ.
//
// τ stands for what is between the loop's output and the metering lands: the servo-valve's own
// dynamics (a 350 Hz, ζ = 0.7 valve acts like 2ζ/ω ≈ 0.64 ms of delay) and any I/O latency. It is
// found by a grid search on the least-squares residual. The run is cut into `segments` parts and
// the fit repeated on each: their spread gives the standard deviations (estimate.hpp).
#pragma once

#include <vector>

#include "control/identification/estimate.hpp"

namespace hsa::control::identification {

struct HydraulicFitOptions {
  double piston_area_m2 = 0.0;  // Ap
  double area_ratio = 0.0;      // α
  double filter_rad_s = 300.0;  // λ: about 3× the plants' natural frequency (√b0 ≈ 90–125 rad/s)
  double max_delay_s = 3e-3;    // the grid of τ: 0 … max in steps of delay_step_s
  double delay_step_s = 5e-5;
  int segments = 5;
};

struct HydraulicFit {
  Estimate stiffness_n_per_m;     // k_h
  Estimate extending_mm_per_s;    // k⁺
  Estimate retracting_mm_per_s;   // k⁻
  double leak_speed_mm_per_s = 0.0;  // v₀
  double delay_s = 0.0;           // τ
};

// Throws std::invalid_argument for records of different lengths, too short for `segments` parts
// of 10 filter time constants, or options that are not positive.
[[nodiscard]] HydraulicFit fit_hydraulics(const std::vector<double>& opening, const std::vector<double>& position_m,
                                          const std::vector<double>& pressure_a_pa,
                                          const std::vector<double>& pressure_b_pa, double period_s,
                                          const HydraulicFitOptions& options);

}  // namespace hsa::control::identification
