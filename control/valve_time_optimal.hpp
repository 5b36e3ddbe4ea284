#pragma once

#include <array>
#include <cstdint>

#include "control/command_delay_line.hpp"
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
//   brake:    I = 0, resp. I_max, from the first sample at which one more sample of full effort
//             would leave no landing: the model, run on through the delay line, then full braking,
//             then the target's hold current I_h from the first braking sample at which I_h stops it
//             at or short of the target, would pass the target (the switching curve);
//   rebuild:  I = I_max, resp. 0, again from the first braking sample at which the model, under
//             full effort until its force current c reaches the target's c_h and then under the
//             settle current, stops at or short of the target. Braking drains c far below c_h (the
//             lag τa); a spool that stopped there would be thrown back by its spring while c crept
//             up at τa. The third full-effort phase of a third-order plant's time-optimal
//             rest-to-rest move, switched here greedily (the drive–brake switch still assumes the
//             hold current after braking), so a spool can still arrive before c is rebuilt;
//   settle:   I = I_h (the model's hold current of the target: + w when the current rises to it,
//             + 0 when it falls to it after the rebuild: eq 6) from the first rebuild sample after
//             which c would pass c_h;
//   hand-back: to the linear law when the model's spool turns (its first stop), or when it turns
//             short of the target under the drive (a target beyond what full effort reaches); the
//             law's reference filter is then set at rest on the target, its integrator held through
//             the move. A new jump of the reference (|r − target| > d_on) starts a new move.
//
// The model is the identified one only (IdentifiedValve: g, X_min, f0, ζ, τa, w, the delay, I_max):
//   the current reference, delayed by δ (whole samples), through the magnetic play of width w (its
//   output p ∈ [I − w, I]; eq 6), a first-order lag τa to the force current c (eq 3), and the spool
//   ẍ = ω0²·(X_min + g·c + b − x) − 2ζω0·ẋ (eqs 1, 2), stepped at T. The model follows every
//   current the law outputs (commanded()), spool included: during a move its x, v, a are the
//   switching curve's state, not the predictor's, which lags the spool by the LVDT's filter (on the
//   variant valve the predictor-based switch braked 0.8 ms late, then far too early once margined).
//   b, the offset between the measured spool and the model's equilibrium, is taken at the trigger
//   (the spool at rest on the previous target) by moving the model's spool onto the measured one,
//   so that a small error of the identified X_min or g does not move the stopping point.
//
// Nothing in update() allocates or throws. A sample runs at most δ + 1 + 2·horizon model steps
// (the pending commands, one braking run and one hold run: about 400 at the identified settings;
// bench_valve_loop times it), and never more than kPredictionBudget.
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
  double margin_m = 0.0;              // land this far short of the target (the model's stop)
  int horizon_samples = 200;          // longest prediction

  bool operator==(const ValveTimeOptimalParams&) const = default;
};

class ValveTimeOptimal {
 public:
  static constexpr int kMaxDelaySamples = CommandDelayLine::kMaxSamples;
  static constexpr int kPredictionBudget = 4000;  // model steps per sample, at most
  enum class Mode : std::uint8_t { track, drive, brake, rebuild, settle };

  // Throws std::invalid_argument (when enabled) for a non-physical model (g, f0, ζ, τa not > 0,
  // w, δ, the margins not >= 0, δ beyond kMaxDelaySamples), a trigger not > 0 or a horizon < 1.
  ValveTimeOptimal(const ValveTimeOptimalParams& params, double period_s, double max_current_a);

  void reset() noexcept;

  // One sample, before the linear law: the current to output while a move runs, NaN while the
  // linear law is in charge. `filtered_reference_m` is r_f before this sample.
  double update(double reference_m, double filtered_reference_m, const PredictorOutput& predicted) noexcept;

  // The current the law output this sample (whichever part decided it): the model's input.
  void commanded(double current_a) noexcept;

  // True on the sample the move ended: the linear law sets its filter at rest on target_m().
  [[nodiscard]] bool handed_back() const { return handed_back_; }
  [[nodiscard]] Mode mode() const { return mode_; }
  [[nodiscard]] double target_m() const { return target_; }
  [[nodiscard]] std::uint64_t moves() const { return moves_; }
  // The model's spool (valid from a move's start on) and its force current.
  [[nodiscard]] PredictorOutput model_state() const { return {model_.x, model_.v, model_.a}; }
  [[nodiscard]] double model_force_a() const { return model_.force; }
  [[nodiscard]] const ValveTimeOptimalParams& params() const { return params_; }

  // The model, from its own play and force but the spool at (x, v, a), run on through the delay
  // line and then under a constant current: the furthest s·x it reaches before its velocity turns
  // (its stopping point in the direction s).
  [[nodiscard]] double stop_under(double current_a, double direction, const PredictorOutput& from) const noexcept;
  // The current that holds the model at `target_m` when it arrives from the side `direction`.
  [[nodiscard]] double hold_current(double target_m, double direction) const noexcept;

 private:
  struct ModelState {
    double play, force, x, v, a;
  };
  // One model step with current reference `current_a` (after the delay) into the play.
  void step(ModelState& s, double current_a, bool averaged) const noexcept;
  // The model after the commands still in the delay line.
  [[nodiscard]] ModelState after_pending() const noexcept;
  // s·x at the first turn of the velocity under a constant current (at most the horizon, and
  // `*steps` model steps, which it counts down).
  [[nodiscard]] double peak_under(ModelState s, double current_a, double direction, int* steps) const noexcept;
  // The drive's and the rebuild's current: I_max towards a higher target, 0 towards a lower one.
  [[nodiscard]] double full_effort() const noexcept { return direction_ > 0.0 ? max_current_a_ : 0.0; }
  // One more sample of the rebuild's full effort would take the force current past c_h.
  [[nodiscard]] bool rebuilt(ModelState s) const noexcept;
  // From s: full effort until rebuilt(), then the settle current: s·x at the first stop (at most
  // the horizon), as peak_under.
  [[nodiscard]] double peak_after_rebuild(ModelState s, int* steps) const noexcept;
  // After one more sample at full effort, full braking followed by the hold current still stops
  // the model at or short of the target.
  [[nodiscard]] bool can_drive_on() const noexcept;

  ValveTimeOptimalParams params_;
  double period_s_ = 1e-4;
  double max_current_a_ = 0.0;
  double w0_ = 0.0;
  double lag_factor_ = 0.0;  // 1 − exp(−T/τa)
  CommandDelayLine delay_line_;  // the last δ commands
  ModelState model_{};  // the model driven by the delayed commands; its spool is set at a move's start
  bool started_ = false;
  double offset_m_ = 0.0;             // b
  Mode mode_ = Mode::track;
  double target_ = 0.0, direction_ = 0.0, hold_ = 0.0;
  double hold_force_a_ = 0.0;  // c_h: the force current that holds the model on the target
  double start_m_ = 0.0;       // the model's spool when the move started
  double settle_ = 0.0;        // the hold current after the rebuild (the current falls to it)
  bool handed_back_ = false;
  std::uint64_t moves_ = 0;
};

// The time-optimal step's settings from the identified valve alone (ValveLawStep::time_optimal):
// the model is `valve`'s, d_on = g·I_max·ω0·T, no margins (the model brakes onto the target and
// hands back when the linear law would not pass it).
ValveTimeOptimalParams identified_time_optimal(const IdentifiedValve& valve, double period_s);

// Enabled, with `valve` as the model (g, X_min, f0, ζ, τa, w, the delay); the trigger, margin and
// horizon left at their defaults for the caller to set.
ValveTimeOptimalParams time_optimal_on(const IdentifiedValve& valve);

}  // namespace hsa::control
