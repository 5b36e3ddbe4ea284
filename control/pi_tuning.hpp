// PI gains for the cylinder loop, tuned over a set of plants (Puglisi et al. 2015, section 4).
//
// The plants are the linear models of eq 41, P(s) = k01·b0 / (s·(s² + b1·s + b0)), one per working
// point (Table A3, or an identified plant set). The gains
//
//   minimise   the worst, over the set, of the 2 % settling time of the closed-loop step and the
//              recovery time after a step disturbance at the valve (loop_analysis.hpp)
//   subject to hsad's gain gate (gain_gate.hpp): a stable closed loop, gain margin ≥
//              min_gain_margin_db and phase margin ≥ min_phase_margin_deg on every plant, and
//              the small-gain condition when the set has an uncertainty model;
//              so what the tuner proposes is what the gate lets through.
//
// Why both times. The cylinder is an integrator, so a P loop already follows a step with no
// steady error, and the step alone is fastest with Ki → 0; the integral is there for what a load
// or a valve offset does, and with Ki → 0 the rod never comes back from it. Judged on both, the
// tuner trades the step's speed against the integral's tail, which is what a user sees on a rig
// that lifts a weight. (The crossover alone has the same flaw as the step: a P loop maximises it.)
//
// Search. The gains are Kp and the integral corner ω_i = Ki/Kp (rad/s), both on log scales. A grid
// over [kp_min, kp_max] × [corner_min, corner_max] finds the best feasible cell (or the gains the
// user starts from, if better); a compass search in log space refines it, halving its step when no neighbour improves, down to 0.1 %. Settling
// is a non-smooth function of the gains, which is why the search needs no derivative. Steps
// during the search take kSearchStepSamples samples; the result is evaluated again at full
// resolution (loop_analysis.hpp), and that is what is reported.
//
// Pure computation, off any real-time thread: about 0.1 ms per candidate over 33 plants for the
// margins, 15 ms with the steps; a tuning takes a few seconds.
#pragma once

#include <cstddef>
#include <optional>

#include "control/gain_gate.hpp"
#include "control/loop_analysis.hpp"

namespace hsa::control {

// Where the search looks: Kp and the integral corner Ki/Kp.
struct SearchBox {
  double kp_min = 10.0;     // m⁻¹ (0.01 per mm)
  double kp_max = 1000.0;   // m⁻¹ (1 per mm)
  double corner_min = 0.5;  // rad/s
  double corner_max = 50.0;
};

inline constexpr int kSearchStepSamples = 4000;

// The gains judged on every plant of the gate's set: the gate's verdict (margins, stability,
// small gain) and the worst step and recovery, with the index of the plant each came from.
struct SetPerformance {
  GateVerdict verdict;
  double worst_settling_s = 0.0;  // NaN when a step does not settle, or not computed
  std::size_t worst_settling_plant = 0;
  double worst_recovery_s = 0.0;  // after a disturbance at the valve; NaN when it never recovers
  std::size_t worst_recovery_plant = 0;
  double worst_overshoot_pct = 0.0;
  std::size_t worst_overshoot_plant = 0;
  double min_crossover_rad_s = 0.0;

  [[nodiscard]] bool feasible() const { return verdict.passed(); }
};

// step_samples = 0 judges with the gate only (the step and recovery figures are then NaN).
// Throws std::invalid_argument as judge_gains does.
SetPerformance evaluate_on_set(const GainGate& gate, const PiGainsSi& gains, int step_samples = kStepSamples);

struct Tuning {
  PiGainsSi gains;
  SetPerformance performance;  // at full step resolution
  int candidates = 0;          // gain pairs evaluated by the search
};

// nullopt when no gains in the box pass the gate. With `start` (the gains running now), the search
// also starts from them, so when they pass the result is never worse than they are. Throws
// std::invalid_argument on an empty set or a box that is empty or not positive.
std::optional<Tuning> tune_pi(const GainGate& gate, const SearchBox& box = {},
                              std::optional<PiGainsSi> start = std::nullopt);

}  // namespace hsa::control
