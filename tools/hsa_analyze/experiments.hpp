// The papers' experiments re-run on the simulated rig in lockstep: the real loop code
// (control/cascade: the PI at 1 kHz and, with the proportional valve, the valve loop at 10 kHz)
// drives the nonlinear rig (sim/rig) at its real step (100 µs). Nothing here reads a clock, so
// every run is deterministic for the rig's seed, and a test can assert on the numbers.
//
// Two drives:
// - direct: Puglisi et al.'s servo-valve; the PI's opening is the valve command;
// - cascade: Canuto et al.'s proportional valve; the PI's opening becomes a spool reference that the
//   valve loop (state predictor + eq 31 law) turns into a solenoid current every 100 µs.
//
// Each function runs one case and returns its metrics; printing is the CLI's job
// (experiment_command.cpp). Positions and errors are in metres, times in seconds. A run given a
// Trace appends its time series to it (the CLI's --csv).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "control/cascade.hpp"
#include "control/pi_controller.hpp"
#include "control/valve_law.hpp"
#include "sim/rig.hpp"

namespace hsa::analyze {

// A number as a trace label writes it: "%g", so 0.5 and 120 stay short.
std::string label_number(double value);

// Time series of one or more runs, written as CSV: a `case` column naming the run, then numeric
// columns. NaN marks a column that does not apply (no spool in direct mode).
class Trace {
 public:
  // Starts a new case; every row until the next begin() carries `label`. All cases of one trace
  // must use the same columns (checked: std::logic_error).
  void begin(const std::string& label, const std::vector<std::string>& columns);
  void add(const std::vector<double>& values);  // one row; must match the columns (std::logic_error)

  // Writes the header and all rows. Throws std::runtime_error if the file cannot be written.
  void write_csv(const std::string& path) const;

  [[nodiscard]] std::size_t rows() const { return rows_.size(); }

 private:
  struct Row {
    std::size_t label;  // index into labels_
    std::vector<double> values;
  };
  std::vector<std::string> columns_;
  std::vector<std::string> labels_;
  std::vector<Row> rows_;
};

enum class Drive {
  direct,   // servo-valve: command = PI opening
  cascade,  // proportional valve: PI → spool reference → valve loop → solenoid current
};

const char* drive_name(Drive drive);

// The PI of every experiment: the paper's gains (Kp = 85 m⁻¹, Ki = 460 m⁻¹s⁻¹) with the
// integrator parked within ±5 µm (5 encoder counts) of the setpoint.
//
// Why the band: the rig's rod has 2 N of dry friction, and while it sticks the chamber pressures
// integrate the valve opening (the oil is soft: Table A3's k_h ≈ 22 kN/m, with the null leakage
// relaxing them over seconds). The paper's bare PI keeps integrating a stuck error of a few µm, so
// by the time the pressures break the rod free the opening is well past the one that holds the
// load, and the rod slips 10–30 µm past the target; the cycle then repeats the other way. Held
// 10 s after the step, the bare PI still hunts in 8 of the 9 cases, by 8–31 µm peak to peak in
// direct mode and 12–34 µm in cascade mode; the first 3 s hide it in direct mode, where the hunt
// builds up more slowly. With the band the proportional term alone moves the rod the last few µm
// and it stays there (tests/analyze/test_experiments.cpp). The price is a rest error of up to about
// the band, against 9–41 µm for a P controller (p-only).
inline constexpr double kIntegralDeadBandM = 5e-6;

// How a cylinder experiment is run. valve (the valve loop) only matters in cascade mode.
struct Setup {
  Drive drive = Drive::direct;
  // The rig: the paper's by default, or a variant (another cylinder, supply or valve). Each run
  // sets its valve kind from `drive` and its starting position and load from the case.
  sim::RigConfig rig{};
  control::PiParams pi{.integral_dead_band_m = kIntegralDeadBandM};
  control::ValveLawParams valve = control::simulated_proportional_valve_law();
  // An LVDT without excitation ripple or noise: shows whether the valve loop relies on the sensor's
  // noise to get through the dead band.
  bool noiseless_lvdt = false;
  Trace* trace = nullptr;  // when set, the run appends its time series
};

// The cases of the paper's Exp. 1 and 2.
inline constexpr double kStepPositionsM[] = {0.050, 0.150, 0.250};
inline constexpr double kLoadsKg[] = {0.0, 3.0, 6.0};
inline constexpr double kSineOmegasRadS[] = {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0};

// "No sustained oscillation": the rod is held at the target until kStepHoldS after the step, and
// the error's peak-to-peak over the last kRestWindowS of the hold stays within this many encoder
// counts (1 µm each). The hold is long on purpose: a stick-slip hunt can take several seconds to
// build up (see kIntegralDeadBandM), and the rod may still make a last slip of a few µm onto the
// target in the first seconds, which is settling, not oscillation.
inline constexpr double kOscillationLimitCounts = 5.0;
inline constexpr double kStepHoldS = 10.0;
inline constexpr double kRestWindowS = 2.0;

// Exp. 1: settle at position_m, then a step of step_m held for kStepHoldS. The trace records the
// first record_s of the response (the paper's figures show the first seconds).
struct StepMetrics {
  double position_m = 0.0;
  double load_kg = 0.0;
  double step_m = 0.0;
  double overshoot_pct = 0.0;        // (peak − target) / step · 100, 0 if it never passes the target
  double settling_s = 0.0;           // last time outside ±2 % of the step, from the step instant
  double rest_peak_to_peak_m = 0.0;  // error peak-to-peak over the last kRestWindowS of the hold
  double rest_peak_to_peak_counts = 0.0;
  double rest_error_m = 0.0;         // mean error (target − position) over the same window
  bool oscillating = false;          // rest_peak_to_peak_counts > kOscillationLimitCounts
};

StepMetrics run_step(double position_m, double load_kg, const Setup& setup = {}, double step_m = 0.010,
                     double record_s = 3.0);

// The trace label of a step case: "150mm_3kg".
std::string step_label(double position_m, double load_kg);

// Appends a predicted step to `trace` as case `label`, in the columns of a cylinder experiment:
// row k at t = k·period_s (k = 1 …, as run_step records the measured one) with the rod at
// position_m + step_m·unit_response[k − 1]; the columns a linear model has no value for (opening,
// pressures, spool) are NaN.
void trace_predicted_step(Trace& trace, const std::string& label, double position_m, double step_m,
                          double period_s, const std::vector<double>& unit_response);

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

SineMetrics run_sine(double omega_rad_s, double load_kg, int periods = 2, const Setup& setup = {});

// Exp. 3: a 0.5 rad/s sine (as Exp. 2) on base_load_kg; added_kg is added at 1.5 periods (mid-stroke,
// rod moving down at full speed) and removed at 2.0 periods (mid-stroke, moving up); the run ends at
// 4 periods. The weight's force goes on and comes off linearly over change_s.
//
// The paper's operator added and removed the weights by hand (section 5.3). A hand takes the
// weight's force over a tenth of a second or more; kHandLoadChangeS is that quick hand. The time
// matters because the oil column is a spring: Table A3 gives k_h = m·b0 ≈ 22 kN/m for the light
// rod, so the 29 N of 3 kg, released in zero time, throws the rod up by ΔF/k_h ≈ 1.3 mm plus the
// overshoot of its 17 Hz mode, which the PI is far too slow to stop (2.2 mm peak error). Spread
// over more than the mode's 60 ms period the release is quasi-static: 1.3 mm at 50 ms, 0.75 mm at
// 0.1 s. change_s = 0 still gives the step, as the worst case.
inline constexpr double kHandLoadChangeS = 0.1;

struct DisturbanceMetrics {
  double base_load_kg = 0.0;
  double added_kg = 0.0;
  double change_s = 0.0;  // time over which the weight goes on or comes off
  double add_s = 0.0;
  double remove_s = 0.0;
  double baseline_error_m = 0.0;  // max |error| from the end of the first period to the load change
  double added_peak_error_m = 0.0;    // max |error| while the extra load is on
  double removed_peak_error_m = 0.0;  // max |error| in the period after it is removed
  double peak_error_m = 0.0;      // max |error| from the end of the first period to the end
  double final_error_m = 0.0;     // max |error| over the last period
  bool stable = false;            // the last period tracks as well as before the disturbance
};

DisturbanceMetrics run_disturbance(double base_load_kg = 0.0, double added_kg = 3.0, const Setup& setup = {},
                                   double change_s = kHandLoadChangeS);

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

HoldMetrics run_hold(double position_m, double load_kg, const Setup& setup, double run_s = 5.0);

}  // namespace hsa::analyze
