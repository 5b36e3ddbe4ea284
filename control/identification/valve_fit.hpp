// Identification of the proportional valve of Canuto et al. (2014), section 2, from an open-loop
// record at the valve rate: the current reference the loop commanded, the solenoid current it
// measured and the LVDT's spool position. The model is valve_model.hpp (eqs 2, 3, 6, 7); the
// current regulator (eq 1) is fitted on its own, from the commanded to the measured current.
//
// What the record can show, and what it cannot:
// - eq 1: the regulator's delay τ, its error e (rms and bound), and the current limit I_max when
//   the command went above it (the measured current then stays at I_max);
// - eq 6: the dead-band width w and the lag τa;
// - eqs 2, 3: the ratios to the moving mass m only. Multiplying m, the spring K, the damping b,
//   the force constant K_f and the friction F_c by one number leaves the current-to-position
//   dynamics unchanged, so without a force measurement m is not identifiable: the record gives
//   f0 = √(K/m)/2π, ζ = b/(2√(K·m)), the static gain g = K_f/K (m/A), s_f = F_c/K, the spring's rest
//   position X_min and the end stop X_max (if the spool reached it). K, b, K_f and F_c are then
//   printed for an assumed m (the paper's 0.1 kg), and scale with it;
// - not at all: eq 2's fluid forces F_f (with no flow and no Δp on the bench they are the damping),
//   LuGre's pre-sliding deformation z (its dynamics are far faster than 0.1 ms), the LVDT's scale
//   error ∂K_s (it multiplies g) and bias b_s (it adds to X_min) of eq 7, which need an external
//   position reference, and the LVDT's bandwidth, taken from its datasheet: its 0.3 ms lag and τa
//   are two lags in series that the record cannot tell apart at the noise of the LVDT.
//
// Method, in three steps, and why:
// 1. Equation error, linear least squares, for a start that needs no guess. Removing τa's lag
//    from eqs 2 and 6 (friction left out) gives, with x seen through the LVDT as y,
//      a3·y⁽³⁾ + a2·ÿ + a1·ẏ + y = g·S·p(t − d·T) + X_min,   S = 1/(τs·s + 1),
//      a3 = τa/ω0², a2 = (1 + 2ζω0τa)/ω0², a1 = 2ζ/ω0 + τa,
//    linear in (a3, a2, a1, g, X_min) once w and d are fixed (p is the play of w on I). The
//    derivatives come from state-variable filters (Young 1981), as in hydraulic_fit.hpp; w and d
//    are a grid search on the residual. τa, ω0 and ζ are the roots of a3·s³ + a2·s² + a1·s + 1.
//    Samples near the stops are left out.
// 2. Output error, Levenberg–Marquardt on the simulation error of valve_model.hpp over w, τa, f0,
//    ζ, g, X_min and s_f. Equation error weights the noise by the derivative filters and leaves
//    friction out, and is biased by both (on the paper's valve: τa 0.94 ms for 1.5, ζ 0.35 for
//    0.3, the delay 0.5 ms for about 0.3); the simulation error is the quantity the fit index
//    measures, and the model carries the dead band, the friction and the stops. The delay δ and
//    τa trade against each other (both are phase lag at f0), and the descent along that valley
//    is slow, so δ is a grid: every half sample from 0 to step 1's d + 1 with six iterations each,
//    then to convergence at the best and a quarter sample either side. Started from step 1's
//    delay alone, the fit stopped at δ = 0.4 ms with τa 8 % low.
// 3. Standard deviations from batch means (estimate.hpp): step 2 repeated on `segments`
//    consecutive parts of the record, each started from the full fit's state at its start.
// The fit index is Puglisi et al.'s eq 39 on the whole record (closed_loop_model.hpp), the
// residual test Ljung's (residual_test.hpp).
#pragma once

#include <vector>

#include "control/identification/estimate.hpp"
#include "control/identification/residual_test.hpp"
#include "control/identification/valve_model.hpp"
#include "control/valve_law.hpp"

namespace hsa::control::identification {

// One row per sample period, SI units. Row k: command_a is the reference held over the period
// that ends at the row's time, current_a and spool_m were read at its end.
struct ValveRecord {
  double period_s = 1e-4;
  std::vector<double> command_a, current_a, spool_m;
};

struct ValveFitOptions {
  double sensor_bandwidth_hz = 500.0;  // the LVDT's (eq 7); a datasheet figure, not fitted
  double assumed_mass_kg = 0.1;        // m, for K, b, K_f, F_c (the paper's: m ≅ 0.1 kg)
  double max_width_a = 1.0;            // step 1's grid of w: 0 … max
  double width_step_a = 0.02;
  int max_delay_samples = 10;          // step 1's grid of d
  double filter_rad_s = 1500.0;        // λ of the state-variable filter: about 5× ω0
  int segments = 5;
  // What a record must have; refused (RunRefused) otherwise.
  double min_duration_s = 2.0;
  double min_current_std_a = 0.05;  // a current that moves across the dead band
  double min_spool_std_m = 50e-6;   // 50 times the LVDT's noise
  int min_current_steps = 20;       // changes of the command larger than the regulator's error
};

struct RegulatorFit {             // eq 1
  double delay_s = 0.0;           // τ
  double error_rms_a = 0.0;       // e, where the current is not limited
  double error_max_a = 0.0;
  bool limit_reached = false;     // the command went above the limit
  Estimate current_max_a;         // I_max if reached
  double largest_command_a = 0.0;
};

struct ValveFit {
  RegulatorFit regulator;
  Estimate width_a, magnetic_lag_s, natural_frequency_hz, damping_ratio, gain_m_per_a, rest_position_m,
      friction_band_m;
  bool end_stop_reached = false;  // the spool stayed at its highest reading for 5 ms or more
  Estimate stroke_max_m;          // X_max if reached
  double delay_s = 0.0;           // δ of valve_model.hpp, current to LVDT
  ValveModel model;               // the fitted model, as simulated
  ValveModel equation_error;      // step 1's start
  // The same for the assumed mass: K = m·ω0², b = 2ζ·m·ω0, K_f = g·K, F_c = s_f·K.
  Estimate stiffness_n_per_m, damping_n_s_per_m, force_constant_n_per_a, friction_n;
  std::vector<double> model_spool_m;
  double fit_index = 0.0;  // Puglisi et al. eq 39
  ResidualTest residuals;
};

// Throws RunRefused (identify_run.hpp) with what to change for a record it cannot identify from:
// columns of different lengths, a non-finite sample, too short, a constant current, too few
// steps, a spool that did not move; and for a fit that gives a non-physical model.
[[nodiscard]] ValveFit fit_valve(const ValveRecord& record, const ValveFitOptions& options = {});

// What the valve law needs of a fit (control/valve_law.hpp): the delay is the regulator's τ plus the
// current-to-LVDT δ. That is one period more than the valve model's own delay from command to
// reading, τ + δ − T. τ counts the period the command is held over, and δ starts from the current
// of that period. The laws behind the model predictor, which has no LVDT lag in its model, were
// designed and measured with τ + δ (docs/valve-loop.md, "the laws' delay"). I_max is the limit
// the record reached, else `current_max_a` (the drive's datasheet figure). Throws RunRefused when
// the limit was not reached and none is given.
[[nodiscard]] IdentifiedValve identified_valve(const ValveFit& fit, double current_max_a = 0.0);

}  // namespace hsa::control::identification
