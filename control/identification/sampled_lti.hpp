// Exact sampling of a continuous linear system ẋ = A·x + B·u for the identification code, for the
// two kinds of input a recorded run holds:
// - a command the loop held constant over each period (zero-order hold), seen through a pure
//   delay τ = d·T + f (0 ≤ f < T): over [t_k, t_k + f) the input is u(k−d−1), then u(k−d), so
//     x(k+1) = Φ·x(k) + Γ_late·u(k−d−1) + Γ_now·u(k−d),
//     Φ = e^{AT},  Γ_late = e^{A(T−f)}·Γ(f),  Γ_now = Γ(T−f),  Γ(h) = ∫₀ʰ e^{Aσ}dσ·B;
// - a measured signal that moves smoothly between samples (first-order hold: straight lines):
//     x(k+1) = Φ·x(k) + Γ₀·u(k) + Γ₁·(u(k+1) − u(k))/T,
//   Φ, Γ₀ and Γ₁ read off e^{M·T} with M = [A B 0; 0 0 1; 0 0 0] (the input and its slope as
//   states).
// The integrals come from the matrix exponential of the augmented matrix, so there is no
// approximation beyond the hold assumption itself.
#pragma once

#include <Eigen/Dense>

namespace hsa::control::identification {

struct HeldInputSampling {
  Eigen::MatrixXd phi;
  Eigen::VectorXd gamma_late, gamma_now;
  int whole_periods = 0;  // d
};

struct SmoothInputSampling {
  Eigen::MatrixXd phi;
  Eigen::VectorXd gamma0, gamma1;
};

// delay_s >= 0.
[[nodiscard]] HeldInputSampling sample_held(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double period_s,
                                            double delay_s);
[[nodiscard]] SmoothInputSampling sample_smooth(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double period_s);

// The state-variable filter both equation-error fits pass every signal through (Young 1981):
// F(s) = λ⁴/(s + λ)⁴ in companion form, whose states are the filtered signal and its derivatives 1…3.
void fourth_order_filter(double lambda, Eigen::MatrixXd& a, Eigen::VectorXd& b);

}  // namespace hsa::control::identification
