#pragma once

// Offline design of the predictive valve law (valve_predictive.hpp) on the valve identified after
// Canuto et al. (2014) section 2: its matrices from the fit, and its settings chosen on the fit's
// own simulation model.
//
// The matrices. The identified model (control/identification/valve_model.hpp: the play at its mean
// w/2 below the current, τa, the spring–mass of g, f0 and ζ, the dry friction band s_f as a known
// force on the target's slope, the LVDT's first-order filter), with an input disturbance and the
// affine terms as states, is discretised exactly at T (zero-order hold, the matrix exponential of
// the system with its inputs). Its command delay is the regulator's τ and the fit's δ less the
// period the command is held over, D = round((τ + δ)/T) − 1 samples (the delay in the fit's own
// terms, as tools/valve-corner-bound composes it). Then:
// - the Kalman gain: the steady state of the filter's Riccati recursion, the disturbance a random
//   walk of `disturbance_walk_a` per sample and the velocity one of `velocity_walk_m_s`, the
//   reading's noise the LVDT's;
// - the cost-to-go S: the steady state of the control Riccati recursion for the stage cost
//   (y − r(i − P))² + ρ·ΔI² on the plant with its reference and φ registers (shifted, the last
//   held), iterated from the stage cost until it settles;
// - the QP: the cost over H = P + `horizon_extra_samples` commands with S at the end, condensed
//   into U ↦ ½·UᵀHU + Uᵀ·F·x0 (µm²: the cost is scaled so that the Cholesky factor works on
//   numbers near 1).
//
// The settings. P, ρ, the dither's share of w, the disturbance's random walk and the share of the
// dither the box keeps off the current's limits are chosen on a grid by the law's peak residual
// (eq 9, valve_triangle_residual.hpp) on the 70 % triangle at 10 Hz, run in closed loop on the fit's simulation model itself: the same model as above but
// with the play driven by the dithered command, Coulomb friction with stiction, the stops, and
// white noise of the LVDT's rms on the reading (a datasheet figure: the fit does not give it),
// averaged over the grid's noise draws. Nothing here knows the simulator; docs/valve-loop.md
// compares this model's ranking of the settings with the simulator's.

#include <cstdint>
#include <vector>

#include "control/identification/valve_fit.hpp"
#include "control/identification/valve_model.hpp"
#include "control/valve_predictive.hpp"

namespace hsa::control {

// What the design needs of an identification (control/identification/valve_fit.hpp).
struct ValvePredictiveValve {
  identification::ValveModel model;  // ValveFit::model
  double regulator_delay_s = 0.0;    // eq 1's τ, counted from the start of the command's period
  double current_max_a = 0.0;        // I_max
  double lvdt_noise_m = 1.03e-6;     // the reading's rms noise
};

// From a fit: its model and regulator delay, and the limit the record reached (else `current_max_a`,
// the drive's datasheet figure; identified_valve()'s refusal when neither is there).
[[nodiscard]] ValvePredictiveValve predictive_valve(const identification::ValveFit& fit, double current_max_a = 0.0);

struct ValvePredictiveSettings {
  int preview_samples = 16;                 // P
  int horizon_extra_samples = 50;           // H − P
  double rate_weight_m2_per_a2 = 1e-10;     // ρ
  double dither_fraction = 1.0;             // the dither's amplitude, a share of w
  double headroom_fraction = 1.0;           // the share of the dither's amplitude the box keeps off 0 and I_max
  double disturbance_walk_a = 1e-5;         // per sample
  // While the target is held (moving by less than the LVDT's noise over the preview): not chosen
  // by the design, whose triangle never holds, but by a cascade's rest, where the spool must not
  // sit off its target in the friction band (docs/valve-loop.md, "In the cascade").
  double held_disturbance_walk_a = 1e-4;
  double velocity_walk_m_s = 1e-5;          // per sample
  double direction_velocity_m_s = 5e-6;     // v_d of the friction's tanh
  int max_qp_iterations = 200;

  bool operator==(const ValvePredictiveSettings&) const = default;
};

// The law's matrices for these settings. `dither_frequency_hz` is 1/(2·n·T) for a whole n.
// Throws std::invalid_argument for a non-physical model, a delay below two periods or above
// CommandDelayLine's reach, a box the dither leaves empty, or settings out of range.
[[nodiscard]] ValvePredictiveParams valve_predictive_params(const ValvePredictiveValve& valve, double period_s,
                                                            double dither_frequency_hz,
                                                            const ValvePredictiveSettings& settings);

// Eq 9's peak residual of the 70 % triangle at 10 Hz (2 periods to settle, 4 scored) under the law,
// on the fit's simulation model, with the reading's noise drawn from `seed`.
[[nodiscard]] double predictive_triangle_peak(const ValvePredictiveValve& valve, const ValvePredictiveParams& law,
                                              std::uint64_t seed);

struct ValvePredictiveGrid {
  std::vector<int> preview_samples{16, 28};
  std::vector<double> rate_weights_m2_per_a2{2e-11, 1e-10, 2e-10};
  std::vector<double> dither_fractions{0.6, 0.75};
  std::vector<double> disturbance_walks_a{1e-6, 1e-5};
  std::vector<double> headroom_fractions{0.5, 1.0};
  std::vector<std::uint64_t> seeds{1, 2};
};

struct ValvePredictiveCandidate {
  ValvePredictiveSettings settings;
  double peak_m = 0.0;  // mean over the grid's seeds
};

struct ValvePredictiveDesign {
  ValvePredictiveSettings settings;  // the chosen ones
  ValvePredictiveParams law;
  double peak_m = 0.0;
  std::vector<ValvePredictiveCandidate> candidates;  // every point of the grid, in the grid's order
};

// The grid point with the least mean peak residual on the fit's model. Throws
// std::invalid_argument for an empty grid or one of valve_predictive_params()'s refusals.
[[nodiscard]] ValvePredictiveDesign design_valve_predictive(const ValvePredictiveValve& valve, double period_s,
                                                            double dither_frequency_hz,
                                                            const ValvePredictiveGrid& grid = {});

}  // namespace hsa::control
