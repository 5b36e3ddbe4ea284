#pragma once

#include <complex>
#include <vector>

#include "control/plant_table.hpp"

namespace hsa::control {

// Linear analysis of the PI cylinder loop (Puglisi et al. 2015, section 4) on one plant of the form
// P(s) = gain / (s·(s² + b1·s + b0)) (plant_table.hpp), continuous time:
//
//   L(s) = (Kp + Ki/s)·P(s)
//   closed loop T(s) = (gain·Kp·s + gain·Ki) / (s⁴ + b1·s³ + b0·s² + gain·Kp·s + gain·Ki)
//
// - poles: eigenvalues of the companion matrix of T's denominator (Table 1 of Puglisi et al. (2015));
// - margins: in closed form. With x = ω², the gain crossovers are the positive roots of a quartic
//   in x (|L|² = 1 cleared of fractions) and the phase crossover is ω² = b0 − Ki·b1/Kp (where
//   arg L = −π; none when that is not positive); the margins are read from L(jω) there, whose
//   phase arg L(jω) = atan2(Kp·ω, Ki) − π − atan2(b1·ω, b0 − ω²) is continuous in ω;
// - step: T in controllable canonical form, discretized exactly (zero-order hold through the
//   matrix exponential of the augmented [A B; 0 0]) on a fine grid, so the samples are the exact
//   continuous response; overshoot is taken on the samples, and the 2 % settling time is the last
//   exit from the ±2 % band, interpolated between samples.
//
// Units: the PI gains are given in SI (valve opening per metre of error, e.g. Kp = 85 m⁻¹,
// Ki = 460 m⁻¹s⁻¹), the plants of Table A3 in millimetres. Every function converts the gains once
// with kMetresPerMillimetre (85 m⁻¹ → 0.085 mm⁻¹, the paper's figures); nothing else depends on
// the unit because the loop is closed on the same quantity.
inline constexpr double kMetresPerMillimetre = 1e-3;

struct PiGainsSi {
  double kp = 85.0;   // m⁻¹
  double ki = 460.0;  // m⁻¹s⁻¹
};

struct StabilityMargins {
  double gain_margin_db;         // +inf when the phase never crosses −180° (above ω = 0)
  double phase_crossover_rad_s;  // where the gain margin is read; NaN when none
  double phase_margin_deg;       // NaN when |L| never crosses 1
  double crossover_rad_s;        // gain crossover; NaN when none
};

struct StepMetrics {
  double overshoot_pct;  // (peak − 1)·100, 0 when the response never exceeds 1; NaN if unstable
  double peak_time_s;    // NaN if unstable
  double settling_s;     // 2 % band; NaN if unstable
};

struct LoopAnalysis {
  std::vector<std::complex<double>> poles;  // slowest (largest real part) first
  bool stable = false;
  StabilityMargins margins{};
  StepMetrics step{};
};

// Throws std::invalid_argument unless kp > 0, ki >= 0 and the plant's coefficients are positive.
// With ki = 0 (P control) the closed loop has order 3.
std::vector<std::complex<double>> closed_loop_poles(const CylinderPlant& plant, const PiGainsSi& gains);
StabilityMargins stability_margins(const CylinderPlant& plant, const PiGainsSi& gains);
// `samples` over 20 time constants of the slowest pole: the default resolves the settling time to
// 1e-4 of the horizon; a search over many gains (pi_tuning.hpp) takes fewer and checks its
// result with the default.
inline constexpr int kStepSamples = 200000;
StepMetrics step_metrics(const CylinderPlant& plant, const PiGainsSi& gains, int samples = kStepSamples);

// The closed loop's unit step response y(k·period_s), k = 1 … samples, exact (the same
// discretization as step_metrics), for plotting it beside a measured step. Unbounded when the loop
// is unstable. Throws std::invalid_argument as the other functions do, or for period_s <= 0 or
// samples < 0.
std::vector<double> step_response(const CylinderPlant& plant, const PiGainsSi& gains, double period_s, int samples);

// The rod's answer to a unit step of valve opening added at the plant's input, Y = P/(1 + K·P)·D
// (a steady load force, or a valve offset, seen as the opening that would cancel it): it peaks
// and the integral brings it back to 0. The recovery time is the last exit from ±2 % of the peak.
// This is what the integral is for: a P loop (Ki = 0) never recovers (NaN), and the smaller Ki/Kp
// the longer the tail, which the reference step alone does not show.
struct DisturbanceMetrics {
  double peak_mm;     // per unit opening; NaN if unstable
  double recovery_s;  // NaN if unstable or never back within 2 % of the peak
};
DisturbanceMetrics disturbance_response(const CylinderPlant& plant, const PiGainsSi& gains,
                                        int samples = kStepSamples);
LoopAnalysis analyze_loop(const CylinderPlant& plant, const PiGainsSi& gains);

}  // namespace hsa::control
