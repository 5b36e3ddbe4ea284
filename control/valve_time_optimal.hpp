#pragma once

#include <array>
#include <cstdint>

#include "control/state_predictor.hpp"

namespace hsa::control {

struct IdentifiedValve;  // valve_law.hpp

// Proximate time-optimal moves of the proportional valve's spool (after Workman's PTOS for disk
// drives, 1987: full effort far from the target, a switching curve for braking, the linear law
// near it), on top of the model-inverse law of valve_law.hpp (Canuto et al. (2014) eq 31 fed the
// identified valve's inverse). The model-inverse law tracks a reference r_f filtered at f_r; a
// step of the reference is, to it, a 300 Hz move whose inverse the current limit clips, and the
// spool moves slower than the physics allows (docs/valve-loop.md, "The slew rate the physics
// allows"). This part takes over for such a step only:
//
//   trigger:  |r − r_f| > d_on, with r_f the reference filter's state before this sample and
//             d_on = g·I_max·ω0·T: no spool of this valve moves that far in one sample (g·I_max·ω0
//             bounds the speed of a spring–mass of gain g and mode ω0 under a current ≤ I_max), so
//             the reference has jumped. A triangle or a sine the filter follows stays far below it
//             (|r − r_f| ≈ 3·ṙ/ω_r on a ramp).
//   drive:    I = I_max towards a higher target, 0 towards a lower one (s = ±1);
//   brake:    I = 0, resp. I_max, from the first sample at which the identified model, run on from
//             the spool's state with the commands still in the delay line and then the braking
//             current, comes to rest at s·x ≥ s·r − margin: that state lies on the switching curve
//             (the set of states from which full braking stops the model at the target);
//   hand-back: to the linear law, as soon as the model run on from the spool's state under that
//             law (the hold current of the target, I_h = I0 + K_r·r + K_i·s, plus k_p·(r − x)
//             − K_v·v − K_a·a, clamped to [0, I_max]) peaks at s·x ≤ s·r + overshoot; the law's
//             reference filter is then set at rest on r, its integrator was held through the
//             move, so the current it outputs is the one the prediction assumed (no bump). A new
//             jump of the reference (|r − target| > d_on) starts a new move.
//
// The model is the identified one only (IdentifiedValve: g, X_min, f0, ζ, τa, w, the delay, I_max):
//   the current reference, delayed by δ (whole samples), through the magnetic play of width w (its
//   output p ∈ [I − w, I]; eq 6), a first-order lag τa to the force current c (eq 3), and the spool
//   ẍ = ω0²·(X_min + g·c + b − x) − 2ζω0·ẋ (eqs 1, 2), stepped at T. The model's c follows every
//   current the law outputs (commanded()); x, v and a come from the state predictor; b, the offset
//   between the measured spool and the model's equilibrium, is taken at the trigger (the spool at
//   rest on the previous target) so that a small error of the identified X_min or g does not move
//   the stopping point. In the linear law's prediction the dither averages the play to I − w/2.
//
// Nothing in update() allocates or throws; a prediction runs at most `horizon_samples` model steps.
struct ValveTimeOptimalParams {
  bool enabled = false;
  // The identified valve (control/identification/valve_fit.hpp), SI.
  double gain_m_per_a = 0.0;          // g
  double rest_position_m = 0.0;       // X_min
  double natural_frequency_hz = 0.0;  // f0
  double damping_ratio = 0.0;         // ζ
  double magnetic_lag_s = 0.0;        // τa
  double width_a = 0.0;               // w
  double delay_s = 0.0;               // δ, rounded to whole samples (at most kMaxDelaySamples)
  double trigger_m = 0.0;             // d_on
  double margin_m = 0.0;              // brake when the full-braking stop is this close to the target
  double overshoot_m = 0.0;           // hand back when the linear law stays within this past it
  int horizon_samples = 200;          // longest prediction

  bool operator==(const ValveTimeOptimalParams&) const = default;
};

// What the linear law outputs near the target, for the hand-back's prediction.
struct ValveLinearLaw {
  double hold_current_a = 0.0;          // I0 + K_i·s: the hold current of r = 0
  double feedforward_a_per_m = 0.0;     // K_r
  double proportional_a_per_m = 0.0;    // k_p
  double dead_band_compensation_a = 0.0;  // ΔI
  double dead_band_error_m = 1e-6;        // e_w
  double velocity_a_per_m_s = 0.0;      // K_v
  double acceleration_a_per_m_s2 = 0.0; // K_a
};

class ValveTimeOptimal {
 public:
  static constexpr int kMaxDelaySamples = 16;
  enum class Mode : std::uint8_t { track, drive, brake };

  // Throws std::invalid_argument (when enabled) for a non-physical model (g, f0, ζ, τa not > 0,
  // w, δ, the margins not >= 0, δ beyond kMaxDelaySamples), a trigger not > 0 or a horizon < 1.
  ValveTimeOptimal(const ValveTimeOptimalParams& params, double period_s, double max_current_a);

  void reset() noexcept;

  // One sample, before the linear law: the current to output while a move runs, NaN while the
  // linear law is in charge. `filtered_reference_m` is r_f before this sample.
  double update(double reference_m, double filtered_reference_m, const PredictorOutput& predicted,
                const ValveLinearLaw& linear) noexcept;

  // The current the law output this sample (whichever part decided it): the model's input.
  void commanded(double current_a) noexcept;

  // True on the sample the move ended: the linear law sets its filter at rest on target_m().
  [[nodiscard]] bool handed_back() const { return handed_back_; }
  [[nodiscard]] Mode mode() const { return mode_; }
  [[nodiscard]] double target_m() const { return target_; }
  [[nodiscard]] std::uint64_t moves() const { return moves_; }
  [[nodiscard]] const ValveTimeOptimalParams& params() const { return params_; }

  // The model run on from (x, v, a) under a constant current after the delay line: the furthest
  // s·x it reaches before its velocity turns (its stopping point in the direction s).
  [[nodiscard]] double stop_under(double current_a, double direction, const PredictorOutput& from) const noexcept;
  // The same under the linear law around `target_m`.
  [[nodiscard]] double stop_under_linear(const ValveLinearLaw& linear, double target_m, double direction,
                                         const PredictorOutput& from) const noexcept;

 private:
  struct ModelState {
    double play, force, x, v, a;
  };
  // One model step with current reference `current_a` (after the delay) into the play, or, when
  // `averaged`, the play at I − w/2 (the linear law's dither).
  void step(ModelState& s, double current_a, bool averaged) const noexcept;
  [[nodiscard]] double predict(const ValveLinearLaw* linear, double constant_a, double target_m, double direction,
                               const PredictorOutput& from) const noexcept;

  ValveTimeOptimalParams params_;
  double period_s_ = 1e-4;
  double max_current_a_ = 0.0;
  double w0_ = 0.0;
  double lag_factor_ = 0.0;  // 1 − exp(−T/τa)
  int delay_samples_ = 0;
  std::array<double, kMaxDelaySamples> delay_line_{};  // the last δ commands, oldest at head_
  int head_ = 0;
  double play_ = 0.0, force_ = 0.0;  // the model's play output and force current, driven by the delayed commands
  bool started_ = false;
  double offset_m_ = 0.0;             // b
  Mode mode_ = Mode::track;
  double target_ = 0.0, direction_ = 0.0;
  bool handed_back_ = false;
  std::uint64_t moves_ = 0;
};

// The time-optimal step's settings from the identified valve alone (ValveLawStep::time_optimal):
// the model is `valve`'s, d_on = g·I_max·ω0·T, no margins (the model brakes onto the target and
// hands back when the linear law would not pass it).
ValveTimeOptimalParams identified_time_optimal(const IdentifiedValve& valve, double period_s);

}  // namespace hsa::control
