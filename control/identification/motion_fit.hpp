// The motion parameters of Puglisi et al. (2015), section 3.2: the moving mass m, the viscous
// friction σ and the external force F_e from the force balance on the rod (eq 33),
//
//   Ap·P_L = m·ÿ + σ·ẏ + F_e + F_c·sign(ẏ),     P_L = P_A − α·P_B,
//
// by least squares on the stacked samples (eq 34), using only the transients: a window of
// window_s (150 ms in the paper) after each change of the setpoint. ẏ and ÿ are central finite
// differences of the position, low-passed by a 4th-order Butterworth at 200 Hz; P_A and P_B are
// low-passed at 400 Hz (section 3.1.1), both zero-phase (zero_phase_filter.hpp says why). The
// filters run over the whole record before the windows are cut, so no window sees a filter's edge.
//
// The value is the least-squares solution over all windows together; its standard deviation
// comes from the spread of the solutions over five runs of consecutive windows (the paper's
// Fig. 7 shows the spread of single windows).
//
// The column F_c·sign(ẏ) is not in the paper's eq 34: it is the seals' dry friction. Left out,
// the friction's force, whose sign follows the velocity, is read as viscous: on the simulated rig
// (2 N of dry friction) σ came out 17 % high with a 2 mm excitation and 2.5× with 0.2 mm, while m
// stayed within 1 %. Samples where the rod is (nearly) still, |ẏ| < min_speed, are left out: there
// the friction is whatever holds the rod, not ±F_c. F_e is what is left: the load's weight.
#pragma once

#include <vector>

#include "control/identification/estimate.hpp"

namespace hsa::control::identification {

struct MotionFitOptions {
  double piston_area_m2 = 0.0;  // Ap
  double area_ratio = 0.0;      // α: annulus over piston area
  double window_s = 0.150;
  double derivative_cutoff_hz = 200.0;
  double pressure_cutoff_hz = 400.0;
  double min_speed_m_s = 2e-3;
};

struct MotionFit {
  Estimate mass_kg;
  Estimate damping_n_s_per_m;  // σ
  Estimate external_force_n;   // F_e
  Estimate dry_friction_n;     // F_c
  int windows = 0;
};

// Throws std::invalid_argument for vectors of different lengths, an area or ratio that is not
// positive, or fewer than 10 windows with a full window_s of data.
[[nodiscard]] MotionFit fit_motion(const std::vector<double>& setpoint_m, const std::vector<double>& position_m,
                                   const std::vector<double>& pressure_a_pa, const std::vector<double>& pressure_b_pa,
                                   double period_s, const MotionFitOptions& options);

}  // namespace hsa::control::identification
