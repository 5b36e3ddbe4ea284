#pragma once

// Offline design of the valve loop's learning filter (control/valve_learning.hpp runs it), on the
// valve identified from a record (IdentifiedValve), never on the simulator's constants.
//
// Canuto et al. (2014) close on rejecting the residual tracking error's peaks at multiples of the
// reference frequency. With a reference of period N·T, the learning law adds to the reference a
// correction u learned from the previous period (reference-modification iterative learning):
//
//   u_{k+1}(i) = Σ_j q_j·u_k(i − j) + Σ_j h_j·e_k(i − j),   j = −M … M,
//   e_k(i)     = r(i − D) − x(i)
//
// k the period, x the predicted spool position, D the loop's own delay (the target is the
// reference delayed by what the loop cannot avoid, so that only the corners' transients are learned).
// Both filters are non-causal within the stored period. Per harmonic f_n = n/(N·T), with G(f) the
// closed loop from the reference to x of the model-inverse law (valve_law.hpp) around the identified
// valve:
//
//   Q(f) = 2^(−(f/f_Q)²/2)            zero-phase Gaussian low-pass, −3 dB at f_Q, never above 1
//   H(f) = k_L·Q(f)/G(f)              the closed loop's inverse, learning gain k_L
//
// and q_j, h_j are their inverse DFTs over the period, truncated to |j| ≤ M. The period-to-period
// map of u is U_{k+1} = (Q − H·G)·U_k + H·E_0, so the learning converges when
//
//   ρ = max_n |Q̃(f_n) − H̃(f_n)·G(f_n)| < 1          (Q̃, H̃: the truncated filters' responses)
//
// (Moore, Iterative Learning Control; Longman 2000). Untruncated, Q − H·G = (1 − k_L)·Q.
//
// G on the identified model (s = j2πf): the valve P(s) = g·e^{−sδ} / ((1 + s·τa)(1 + 2ζs/ω0 + s²/ω0²))
// (Canuto et al. (2014) eqs 2, 3, 6 linearised, δ the identified delays), the law's reference
// filter F(s) = ω_r³/(s + ω_r)³, its feed-forward C_r(s) = K_r + K_rv·s + K_ra·s² + K_rj·s³ + k_p + K_i/s
// on r_f and its feedback C_x(s) = k_p + K_i/s + K_v·s + K_a·s² on x:
//
//   G(s) = F(s)·P(s)·C_r(s) / (1 + P(s)·C_x(s)) · e^{−1.5·sT}
//
// the last factor the zero-order hold's half sample and the sample between the law's output and the
// LVDT reading it. Linearised: K_p(e) taken at its far slope k_p, the predictor taken as exact, the
// dead band and the dither left out; ρ's margin below 1 is what covers them.

#include <complex>
#include <vector>

#include "control/valve_law.hpp"

namespace hsa::control {

struct ValveLearningSettings {
  double filter_hz = 0.0;    // f_Q
  double gain = 0.0;         // k_L, in (0, 2)
  int half_width = 0;        // M (at most (N − 1)/2)
  int settle_periods = 0;    // periods an experiment lets it learn before it is scored
};

// The settings identified_valve_law() uses (valve_learning_design.cpp says how they were chosen).
ValveLearningSettings valve_learning_settings();

struct ValveLearningDesign {
  int period_samples = 0;      // N
  int delay_samples = 0;       // D = round(−arg G(f_1)/(2π·f_1·T))
  std::vector<double> filter;  // q_j, j = −M … M (index j + M)
  std::vector<double> kernel;  // h_j, j = −M … M
  double convergence = 0.0;    // ρ above
};

// G(j2πf) above for the law `law` (its model-inverse terms and feedback) around `valve`.
std::complex<double> valve_loop_response(const IdentifiedValve& valve, const ValveLawParams& law, double frequency_hz);

// The learning filter for a reference of N = period_samples samples. Throws std::invalid_argument
// for N < 4, f_Q ≤ 0, k_L outside (0, 2) or M < 1.
ValveLearningDesign design_valve_learning(const IdentifiedValve& valve, const ValveLawParams& law, int period_samples,
                                          const ValveLearningSettings& settings);

// ρ_n = |Q̃(f_n) − H̃(f_n)·G(f_n)| for n = 0 … N/2: the convergence factor harmonic by harmonic.
std::vector<double> valve_learning_convergence(const IdentifiedValve& valve, const ValveLawParams& law,
                                               const ValveLearningDesign& design);

}  // namespace hsa::control
