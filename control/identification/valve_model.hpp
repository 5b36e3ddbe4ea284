// The proportional valve's model as the identification sees it: from the measured solenoid
// current to the LVDT reading, Canuto et al. (2014), eqs 2, 3, 6 and 7, with every force divided
// by the moving mass m (a current-to-position record has no force in it, see valve_fit.hpp):
//
//   dead band (eq 6)      p = play of width w on I(t − δ):  p ∈ [I − w, I], moved only by the edges
//   magnetic lag (eq 6)   τa·ċ = p − c
//   spool (eqs 2, 3)      ẍ = ω0²·(g·c − (x − X_min)) − 2ζω0·ẋ − ω0²·s_f·sgn(ẋ),   X_min ≤ x ≤ X_max
//   LVDT (eq 7)           τs·ẏ = x − y,   τs = 1/(2π·sensor bandwidth)
//
// ω0 = 2π·f0 = √(K/m), ζ = b/(2√(K·m)), g = K_f/K the static spool travel per ampere, X_min the
// spring's rest position (the rest stop), s_f = F_c/K the half-width of the band in which dry
// friction holds the spool (the LuGre friction of eqs 2 and 4 reduced to Coulomb friction with
// stiction). The pure delay δ stands for what lies between the current sample and the LVDT
// sample that first sees it: the sample-and-hold of the loop and the board's anti-aliasing filter
// (section 2.3, about 0.2 ms of group delay); it is resolved to the integration substep.
//
// Discretization: the current is held over each sample period; the lag is exact over a substep,
// the spool is integrated in substeps of at most 25 µs by symplectic Euler with implicit damping
// (ω0·h = 0.008 at 50 Hz), and the stops absorb the impact. The LVDT lag is exact per sample.
// The current is held over each sample period, and delayed by δ it changes within one.
#pragma once

#include <cstddef>
#include <vector>

namespace hsa::control::identification {

struct ValveModel {
  double width_a = 0.3;                // w
  double magnetic_lag_s = 1.5e-3;      // τa
  double natural_frequency_hz = 50.0;  // f0
  double damping_ratio = 0.3;          // ζ
  double gain_m_per_a = 1.8e-3;        // g = K_f/K
  double rest_position_m = -2.5e-3;    // X_min
  double friction_band_m = 20e-6;      // s_f = F_c/K
  double stroke_max_m = 1.25e-3;       // X_max (+inf: no end stop)
  double delay_s = 3e-4;               // δ, rounded to the substep
  double sensor_bandwidth_hz = 500.0;  // the LVDT's, eq 7
};

// The model state at one sample, to start a simulation mid-record.
struct ValveModelState {
  double play_a = 0.0, force_current_a = 0.0, position_m = 0.0, velocity_m_s = 0.0, sensor_m = 0.0;
};

// At rest at position_m (clamped to the stroke): the lag and play settled on the current that
// balances the spring there, the LVDT on the position.
[[nodiscard]] ValveModelState rest_state(const ValveModel& model, double position_m);

// The LVDT reading after each sample period first … last − 1 of current_a (the current measured in
// that period), from `start`, the state before sample `first`. Samples before the first current
// (the delay) use current_a.front(). If states is not null, it receives the state before each
// simulated sample (states[0] = start).
[[nodiscard]] std::vector<double> simulate_valve(const ValveModel& model, const std::vector<double>& current_a,
                                                 double period_s, const ValveModelState& start, std::size_t first,
                                                 std::size_t last, std::vector<ValveModelState>* states = nullptr);

}  // namespace hsa::control::identification
