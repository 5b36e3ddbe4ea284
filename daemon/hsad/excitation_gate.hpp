// The checks an excitation (command_t.EXCITE, `hsactl excite`) passes on the operator thread
// before the RT thread runs it: refused with the reason here, it never starts. The supervisor's
// faults stay armed while it runs; these checks refuse a run that would trip them, or run unstable,
// by design. Each bound, for the P loop the excitation runs (Puglisi et al. 2015, section 3.1.1:
// opening = kp·(r − y), the integral off) on the paper's plant, type I and third order,
// P(s) = k01·b0 / (s·(s² + b1·s + b0)) (control/plant_table.hpp, eqs 38 and 41):
//
// - Switching time: at least kMinSwitchingS (10 cylinder-loop samples at 1 kHz: a level the loop
//   holds for fewer is no test of the plant) and at most the duration (one level is no sequence).
// - Soft limits: working point ± amplitude inside them, as every setpoint of the run is.
// - Following error: the largest setpoint step the loop meets is Δ = max(2·amplitude,
//   |working point − rod| + amplitude) (level to level, or from the rod to the first level). A P
//   loop's error right after a step is the step, and then shrinks (its underdamped overshoot
//   undershoots the error by less than the step), so Δ must stay under max_following_error_m.
// - Speed: the opening right after that step is u = min(kp·Δ, 1), and the rod's no-load speed at
//   an opening u is u·k01 (k01: the no-load speed at full opening; a load slows it). With k01 the
//   largest of Table A3 (294 mm/s) that quasi-static peak must stay within max_speed_m_s, the
//   axis's speed bound (its encoder-jump fault allows that speed). It is an estimate: the opening
//   shrinks as the rod closes the error, which the resonance's overshoot of the speed (damping
//   b1/(2√b0) ≈ 0.5 in Table A3) does not outweigh on these plants.
// - Stability: Routh on s³ + b1·s² + b0·s + k01·b0·kp gives kp < b1/k01 (kp per mm); the gain
//   margin 20·log10(b1/(k01·kp)) is computed by control::stability_margins with ki = 0 on every
//   plant of Table A3 (all rod positions and loads), and the worst must be at least
//   kMinGainMarginDb. 4 dB, not the 6 dB usual for a PI in operation: the identification wants an
//   underdamped loop (the paper's kp = 0.2 per mm, whose worst plant, 290 mm with 6 kg, has
//   4.9 dB), the run is short and supervised, and 4 dB still leaves a factor 1.58 on kp for a
//   plant beyond the table's spread. The plants are the paper's cylinder: on another rig the
//   bounds are as good as the table is for it.
#pragma once

#include <string>

#include "daemon/supervisor/axis_supervisor.hpp"
#include "daemon/supervisor/command.hpp"

namespace hsa::daemon::excitation_gate {

inline constexpr double kMinSwitchingS = 0.01;
inline constexpr double kMinGainMarginDb = 4.0;

// The worst gain margin of the P loop of gain kp_per_m over the plants of Table A3, and which.
struct WorstMargin {
  double gain_margin_db = 0.0;
  int position_mm = 0;
  int load_kg = 0;
  double routh_limit_per_mm = 0.0;  // b1/k01 of that plant
};
[[nodiscard]] WorstMargin worst_gain_margin(double kp_per_m);

// "" when the excitation may run with the rod at rod_m, else why not, with the numbers. The
// request's working point is resolved already (at_rod: the rod's position).
[[nodiscard]] std::string refusal(const ExcitationRequest& request, const SupervisorParams& axis, double rod_m);

}  // namespace hsa::daemon::excitation_gate
