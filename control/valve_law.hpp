#pragma once

#include <cstdint>

#include "control/state_predictor.hpp"

namespace hsa::control {

// Digital control law of the proportional valve's spool loop, Canuto et al. (2014) section 3.5, eq 31:
//
//   I(i)     = clamp(I0 + K_r·r(i) + K_i·s(i) + K_p(e(i)) - K_v·v(i) - K_a·a(i),  0, I_max)
//   s(i+1)   = s(i) + T·e(i)        (skipped while frozen, see anti-windup)
//   e(i)     = r(i) - x(i)
//
// r is the spool position reference, and x, v, a the position, velocity and acceleration of the
// state predictor (eqs 15–16). Everything is in SI: the paper's gains act on the predictor's
// per-sample increments and on error voltages, with b and K_s folding them into a current; here
// each gain maps its own physical quantity to amperes (K_r, K_p in A/m, K_i in A/(m·s),
// K_v in A/(m/s), K_a in A/(m/s²)), and s is the time integral of the error. The paper's gains
// convert as K_r = b·K_dr, K_i = b·K_di/T, K_v = b·K_dv·T, K_a = b·K_da·T², with b in A per
// unit of the bracket.
//
// Signs: the solenoid pulls the spool towards positive x against its return spring, so current
// and position rise together. The error terms (integral and K_p) therefore enter with a positive
// sign; eq 31 as printed writes them with a minus, which with this plant would be positive
// feedback (the paper's voltage conventions are not stated). Velocity and acceleration are
// damping and enter negatively, as the paper's derivative actions act on the measurement.
//
// K_p(e) is the smooth monotonic error function that replaces the analogue piecewise curve
// (Fig. 5) and inverts the solenoid's dead band (eqs 6, 32):
//
//   K_p(e) = k_p·e + ΔI·tanh(e / e_w)
//
// Its slope is k_p + ΔI/e_w at e = 0 and falls smoothly to k_p for |e| >> e_w; it is odd,
// strictly increasing, and adds at most ±ΔI. Choosing ΔI as half the dead band's width in current
// (about 0.15 A for the 0.3 A of Canuto et al. (2014)) lets a small error cross the dead band at once
// instead of waiting for the integrator, which is the delay of 20–30° the paper removes.
//
// I0 is the bias current that holds the spool at hydraulic zero: with r = x = v = a = 0 and an
// empty integrator the law outputs exactly I0 (plus the dither, when it is on).
//
// Dither (not in Canuto et al. (2014); standard in proportional-valve amplifiers): a square wave ±A_d at f_d
// is added to the output. An amplitude above half the dead band's width keeps the magnetic play
// moving, so the mean force follows the mean current instead of sticking in the band. The
// 1.5 ms magnetic lag and the 50 Hz spool take most of it off before it reaches the spool.
//
// Skipped samples: update(..., elapsed) with elapsed = m > 1 means m − 1 samples were missed. The
// error of the last sample held over them (zero-order hold, the same assumption as the output it
// produced), so before this sample's output the integral catches up by (m − 1)·T·e(i−m) when
// that sample integrated; the dither's phase advances by m. With m = 1 nothing changes.
//
// Anti-windup on the clamp by conditional integration: the integrator holds while the unclamped
// current is above I_max with e > 0, or below 0 with e < 0.
struct ValveLawParams {
  double period_s = 1e-4;          // T: the valve loop runs at 10 kHz
  double bias_current_a = 0.0;     // I0
  double max_current_a = 3.0;      // I_max
  double feedforward_a_per_m = 0.0;                 // K_r
  double integral_a_per_m_s = 0.0;                  // K_i
  double proportional_a_per_m = 0.0;                // k_p: slope of K_p(e) far from zero
  double dead_band_compensation_a = 0.0;            // ΔI
  double dead_band_error_m = 1e-6;                  // e_w: error over which ΔI is reached
  double velocity_a_per_m_s = 0.0;                  // K_v
  double acceleration_a_per_m_s2 = 0.0;             // K_a
  double dither_amplitude_a = 0.0;                  // A_d, 0 = off
  double dither_frequency_hz = 0.0;                 // f_d = 1/(2·n·T), n whole

  bool operator==(const ValveLawParams&) const = default;
};

// Gains for the simulated proportional valve of Canuto et al. (2014) (sim/proportional_valve with
// its default parameters), to be used with the Table 2 predictor (γ = {0.4, 0.4, 0.04, 0.04}) at
// T = 1e-4 s. See valve_law.cpp for how they were tuned. A real valve needs its own: these know the simulator's spring, force
// constant and dead band.
ValveLawParams simulated_proportional_valve_law();

class ValveLaw {
 public:
  // Throws std::invalid_argument for a non-positive period, I_max or e_w, a bias outside
  // [0, I_max], negative gains, a dither amplitude outside [0, I_max/2], or a dither frequency
  // that is not 1/(2·n·T).
  explicit ValveLaw(const ValveLawParams& params);

  // Empties the integrator.
  void reset(double integral_m_s = 0.0) noexcept;

  // One sample: returns the solenoid current reference in [0, I_max].
  // `elapsed` (>= 1; 0 counts as 1): samples T since the last update.
  double update(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed = 1) noexcept;

  // K_p(e) above, in amperes.
  [[nodiscard]] double error_function(double error_m) const noexcept;

  [[nodiscard]] double current() const { return current_; }
  [[nodiscard]] double error() const { return error_; }
  [[nodiscard]] double integral() const { return integral_; }
  [[nodiscard]] bool saturated() const { return saturated_; }
  [[nodiscard]] std::uint64_t saturation_count() const { return saturation_count_; }
  [[nodiscard]] const ValveLawParams& params() const { return params_; }

 private:
  double dither(std::uint64_t elapsed) noexcept;
  ValveLawParams params_;
  double integral_ = 0.0;
  double error_ = 0.0;
  double current_ = 0.0;
  bool saturated_ = false;
  bool integrated_ = false;  // the last sample's error went into the integral
  std::uint64_t saturation_count_ = 0;
  std::uint32_t dither_half_period_samples_ = 0;
  std::uint32_t dither_phase_ = 0;
};

}  // namespace hsa::control
