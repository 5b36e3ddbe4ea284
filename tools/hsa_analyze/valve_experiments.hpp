// The valve experiments of Canuto et al. (2014) section 4, on the rig's proportional valve.
//
// Only the valve loop runs (predictor + law at 10 kHz), with the spool reference as the input;
// the valve is sim/proportional_valve with `plant`'s parameters (default: the paper's);
// the rod starts at 150 mm without load and moves with the opening, which for these references
// averages to zero. Strokes are fractions of the control stroke ±1.25 mm (100 % = 2.5 mm peak to
// peak), so a 70 % triangle swings ±0.875 mm. Everything is measured on the LVDT, as in the paper.
// `rig_seed` seeds the rig's noise (sim::RigConfig::seed: the LVDT's noise, the regulator's
// error): the figures are one draw of that noise, and another seed gives another draw of the
// same experiment (docs/valve-loop.md has the spread of the peak residual).
#pragma once

#include <cstdint>
#include <vector>

#include "sim/proportional_valve.hpp"

#include "control/valve_law.hpp"
#include "tools/hsa_analyze/experiments.hpp"

namespace hsa::analyze {

inline constexpr double kValveStrokeM = 1.25e-3;  // half the control stroke: the spool reference limit
inline constexpr double kValveSineFrequenciesHz[] = {1, 2, 5, 10, 20, 30, 50, 70, 100, 120, 150, 200, 250, 300};

// Triangle (Fig. 10): the delay τ is the shift that best fits x(t) ≈ r(t − τ) (least squares over
// the last periods); the residual tracking error of eq 9 is η = x(t) − r(t − τ).
struct ValveTriangleMetrics {
  double fraction = 0.0;
  double frequency_hz = 0.0;
  double delay_s = 0.0;
  double residual_max_m = 0.0;  // max |η|
  double residual_rms_m = 0.0;
  // η split over the scored periods into its mean at each phase (what repeats, and what a learning
  // law could remove) and the rest (what differs from period to period: noise through the loop).
  double repeating_max_m = 0.0;
  double repeating_rms_m = 0.0;
  double nonrepeating_max_m = 0.0;
  double nonrepeating_rms_m = 0.0;
};

ValveTriangleMetrics run_valve_triangle(double fraction = 0.70, double frequency_hz = 10.0,
                                        const control::ValveLawParams& valve = control::simulated_proportional_valve_law(),
                                        const sim::ProportionalValveParameters& plant = {}, Trace* trace = nullptr,
                                        std::uint64_t rig_seed = 1);

// Small-signal sine (Figs 11, 12): gain and phase of the LVDT's fundamental against the reference.
struct ValveSineMetrics {
  double fraction = 0.0;
  double frequency_hz = 0.0;
  double gain_db = 0.0;
  double phase_deg = 0.0;  // negative: lag
  double delay_s = 0.0;    // −phase / ω
};

ValveSineMetrics run_valve_sine(double fraction, double frequency_hz,
                                const control::ValveLawParams& valve = control::simulated_proportional_valve_law(),
                                const sim::ProportionalValveParameters& plant = {}, Trace* trace = nullptr,
                                std::uint64_t rig_seed = 1);

// The frequency at which the gain of a sweep (sorted by frequency) first falls below −3 dB,
// interpolated linearly in dB between the sweep's points; +inf if it never does.
double minus_3db_frequency_hz(const std::vector<ValveSineMetrics>& sweep);

// Square wave (Fig. 9): slew rate as the mean 10–90 % slope of the transitions, and the residual
// error (eq 9, where the reference rate is 0) over the second half of each half period.
struct ValveSquareMetrics {
  double fraction = 0.0;
  double frequency_hz = 0.0;
  double slew_rate_m_s = 0.0;
  double rise_10_90_s = 0.0;
  double overshoot_pct = 0.0;    // of the step (2 × amplitude), largest of the scored transitions
  double settled_error_m = 0.0;  // max |r − x| over the second half of each half period
  // max |r − x| from a transition's arrival (the first turn of x after its 90 % crossing) to the
  // half period's middle: an overshoot, or a spool thrown back after it first stopped.
  double arrival_error_m = 0.0;
};

ValveSquareMetrics run_valve_square(double fraction = 0.50, double frequency_hz = 10.0,
                                    const control::ValveLawParams& valve = control::simulated_proportional_valve_law(),
                                    const sim::ProportionalValveParameters& plant = {}, Trace* trace = nullptr,
                                    std::uint64_t rig_seed = 1);

// The fastest 10–90 % transition of the square wave the valve allows (docs/valve-loop.md): the
// valve of sim/proportional_valve open loop, from rest at ∓a (its hold current, eq 5), with its
// current reference at I_max (rising) or 0 (falling) from the step on. Over the first half period
// of the spool mode the current-to-position impulse response is positive, so no current in
// [0, I_max] puts the spool further at any instant: t90 is the earliest possible, and the 10–90 %
// time of the full-effort move is the bound the slew rate is measured against. Measured on the
// spool itself (the LVDT's lag delays both crossings alike).
struct ValveSlewBound {
  double rise_up_s = 0.0, rise_down_s = 0.0;  // 10–90 % under I_max, under 0
  double slew_rate_m_s = 0.0;                 // 0.8 · 2a / mean of the two, as the square's
};
ValveSlewBound valve_slew_bound(double fraction = 0.50, const sim::ProportionalValveParameters& valve = {});

}  // namespace hsa::analyze
