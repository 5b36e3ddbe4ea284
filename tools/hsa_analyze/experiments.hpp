// The papers' experiments (paper 000, section 5) re-run on the simulated rig in lockstep, servo-valve
// (direct) mode: the real PI (control/pi_controller) at its real rate (1 kHz) drives the nonlinear
// rig (sim/rig) at its real step (100 µs, so 10 rig steps per PI sample). Nothing here reads a
// clock, so every run is deterministic for the rig's seed, and a test can assert on the numbers.
//
// Each function runs one case and returns its metrics; printing is the CLI's job
// (experiment_command.cpp). Positions and errors are in metres, times in seconds.
#pragma once

#include <vector>

#include "control/pi_controller.hpp"

namespace hsa::analyze {

// The cases of the paper's Exp. 1 and 2.
inline constexpr double kStepPositionsM[] = {0.050, 0.150, 0.250};
inline constexpr double kLoadsKg[] = {0.0, 3.0, 6.0};
inline constexpr double kSineOmegasRadS[] = {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0};

// "No sustained oscillation": the error's peak-to-peak over the last 0.5 s of the run stays below
// this many encoder counts (1 µm each). A few counts allows for quantization and stick-slip.
inline constexpr double kOscillationLimitCounts = 5.0;

// Exp. 1: settle at position_m, then a step of step_m; the response is recorded for run_s.
struct StepMetrics {
  double position_m = 0.0;
  double load_kg = 0.0;
  double step_m = 0.0;
  double overshoot_pct = 0.0;        // (peak − target) / step · 100, 0 if it never passes the target
  double settling_s = 0.0;           // last time outside ±2 % of the step, from the step instant
  double tail_peak_to_peak_m = 0.0;  // error peak-to-peak over the last 0.5 s
  double tail_peak_to_peak_counts = 0.0;
  bool oscillating = false;          // tail_peak_to_peak_counts > kOscillationLimitCounts
};

StepMetrics run_step(double position_m, double load_kg, double step_m = 0.010, double run_s = 3.0,
                     const control::PiParams& pi = {});

// The spread the paper asks for across the nine cases.
struct StepSpread {
  double overshoot_spread_pts = 0.0;  // max − min, percentage points
  double settling_spread = 0.0;       // max / min − 1 (0.1 = 10 %)
};

StepSpread step_spread(const std::vector<StepMetrics>& cases);

// Exp. 2: y_r(t) = 150 mm + 125 mm · sin(ω t) for `periods` periods, starting at rest at 150 mm.
struct SineMetrics {
  double omega_rad_s = 0.0;
  double load_kg = 0.0;
  int periods = 0;
  double max_error_m = 0.0;  // max |y_r − y| at the PI samples after the first period
};

SineMetrics run_sine(double omega_rad_s, double load_kg, int periods = 2, const control::PiParams& pi = {});

// Exp. 3: a 0.5 rad/s sine (as Exp. 2) on base_load_kg; added_kg is added at 1.5 periods (mid-stroke,
// rod moving down at full speed) and removed at 2.0 periods (mid-stroke, moving up); the run ends at
// 4 periods.
struct DisturbanceMetrics {
  double base_load_kg = 0.0;
  double added_kg = 0.0;
  double add_s = 0.0;
  double remove_s = 0.0;
  double baseline_error_m = 0.0;  // max |error| from the end of the first period to the load change
  double added_peak_error_m = 0.0;    // max |error| while the extra load is on
  double removed_peak_error_m = 0.0;  // max |error| in the period after it is removed
  double peak_error_m = 0.0;      // max |error| from the end of the first period to the end
  double final_error_m = 0.0;     // max |error| over the last period
  bool stable = false;            // the last period tracks as well as before the disturbance
};

DisturbanceMetrics run_disturbance(double base_load_kg = 0.0, double added_kg = 3.0,
                                   const control::PiParams& pi = {});

// P-only against PI: hold position_m under load_kg; the steady error is measured over the last
// second of a run_s hold. A P controller needs a standing error to hold the opening that makes up
// for the valve's null leakage under the gravity load; the PI's integral provides it instead.
struct HoldMetrics {
  double position_m = 0.0;
  double load_kg = 0.0;
  double kp = 0.0;
  double ki = 0.0;
  double mean_error_m = 0.0;     // mean of (setpoint − y) over the last second
  double max_abs_error_m = 0.0;  // max |setpoint − y| over the last second
};

HoldMetrics run_hold(double position_m, double load_kg, const control::PiParams& pi, double run_s = 5.0);

}  // namespace hsa::analyze
