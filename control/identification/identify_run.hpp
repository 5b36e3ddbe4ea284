// Identification of the cylinder at one working point from a closed-loop run under a
// proportional controller with a PRMS or PRBS on the setpoint (Puglisi et al. 2015, section 3;
// control/excitation_sequence.hpp makes the excitation):
// 1. the run is checked, and refused with what to change (RunRefused) when it cannot give a
//    trustworthy plant: too short, too little excitation, a saturated valve, an opening that is
//    not K·(r − y) (not a P loop), or a non-finite sample;
// 2. the P gain K and the loop's offset are read from the run: xv = K·(r − y) + c by least squares;
// 3. m, σ, F_e (eqs 33–34) from the force balance on the rod (motion_fit.hpp);
// 4. the stiffness k_h, the valve's speed gains k01 (extending and retracting) and the delay τ
//    from the load-pressure equation (hydraulic_fit.hpp);
// 5. the plant (eqs 19–21 with the rig's σ holding all the damping): b0 = k_h/m, b1 = σ/m,
//    k01, with standard deviations propagated to first order from the independent fits.
//    The paper identifies the closed loop G_cl from setpoint to position (eq 31) and recovers the
//    open loop with the known P gain (eq 32). A position-only fit cannot tell the seals' dry
//    friction from the dynamics: on the simulated rig it gave b0 5,041 against the small-signal
//    11,469 with a 0.2 mm PRMS and b1 12 % high with 2 mm (docs/control.md, "Identification of a rig").
//    The pressures split the plant where friction acts, so each half can be fitted exactly;
//    K is then used where eq 31 uses it, to simulate G_cl for the fit index;
// 6. the identified G_cl simulated on the run's setpoint (closed_loop_model.hpp), its fit index
//    (eq 39), and the residual test (residual_test.hpp).
//
// Pure: the caller reads the file (hsa-analyze identify) and hands in the samples.
#pragma once

#include <stdexcept>
#include <string>
#include <cstddef>
#include <vector>

#include "control/identification/motion_fit.hpp"
#include "control/identification/hydraulic_fit.hpp"
#include "control/identification/plant_estimate.hpp"
#include "control/identification/residual_test.hpp"

namespace hsa::control::identification {

// One record of the loop, one entry per period, SI units.
struct ClosedLoopRun {
  double period_s = 1e-3;
  std::vector<double> setpoint_m, position_m, opening, pressure_a_pa, pressure_b_pa;
  std::size_t off_grid_samples = 0;  // taken a base tick or two from their loop period (the reader's count)
};

// The limits a run must meet. The defaults suit the paper's rig at 1 kHz.
struct RunLimits {
  double min_duration_s = 10.0;
  int min_setpoint_changes = 20;
  double min_position_std_m = 50e-6;   // 50 encoder counts of 1 µm
  double saturation = 0.98;            // |xv| at or above this counts as saturated …
  double max_saturated_fraction = 1e-3;  // … and more than this share of the samples refuses the run
  double max_p_law_misfit = 0.05;      // rms(xv − K·e − c) / rms(xv − mean): above, not a P loop
};

struct IdentifyOptions {
  HydraulicFitOptions hydraulics{};  // its piston area and area ratio are also the motion fit's
  MotionFitOptions motion{};
  RunLimits limits{};
};

struct Identification {
  double duration_s = 0.0;
  double working_point_m = 0.0;  // mean setpoint
  double kp_per_m = 0.0;         // the run's P gain
  double peak_opening = 0.0;     // max |xv|
  PlantEstimate plant;
  MotionFit motion;
  HydraulicFit hydraulics;
  std::vector<double> model_position_m;  // G_cl's answer to the run's setpoint
  double fit_index = 0.0;                // eq 39
  ResidualTest residuals;
};

// Why a run cannot be identified, and what to change; never turned into numbers.
class RunRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[nodiscard]] Identification identify_run(const ClosedLoopRun& run, const IdentifyOptions& options);

}  // namespace hsa::control::identification
