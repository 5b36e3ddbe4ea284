#include "control/identification/sampled_lti.hpp"

#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

namespace hsa::control::identification {
namespace {

// e^{A h} and Γ(h) = ∫₀ʰ e^{Aσ}dσ·B, from the exponential of [A B; 0 0]·h.
std::pair<Eigen::MatrixXd, Eigen::VectorXd> zoh(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double h) {
  const auto n = a.rows();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 1, n + 1);
  m.topLeftCorner(n, n) = a * h;
  m.topRightCorner(n, 1) = b * h;
  const Eigen::MatrixXd e = m.exp();
  return {e.topLeftCorner(n, n), e.topRightCorner(n, 1)};
}

}  // namespace

HeldInputSampling sample_held(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double period_s, double delay_s) {
  HeldInputSampling s;
  s.whole_periods = static_cast<int>(std::floor(delay_s / period_s + 1e-9));
  const double f = std::max(0.0, delay_s - s.whole_periods * period_s);
  const auto [phi_f, gamma_f] = zoh(a, b, f);
  const auto [phi_rest, gamma_rest] = zoh(a, b, period_s - f);
  s.phi = phi_rest * phi_f;
  s.gamma_late = phi_rest * gamma_f;
  s.gamma_now = gamma_rest;
  return s;
}

SmoothInputSampling sample_smooth(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double period_s) {
  const auto n = a.rows();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 2, n + 2);
  m.topLeftCorner(n, n) = a;
  m.block(0, n, n, 1) = b;
  m(n, n + 1) = 1.0;
  const Eigen::MatrixXd e = (m * period_s).exp();
  return {e.topLeftCorner(n, n), e.block(0, n, n, 1), e.block(0, n + 1, n, 1)};
}

void fourth_order_filter(double lambda, Eigen::MatrixXd& a, Eigen::VectorXd& b) {
  a = Eigen::MatrixXd::Zero(4, 4);
  for (int i = 0; i < 3; ++i) a(i, i + 1) = 1.0;
  const double l2 = lambda * lambda;
  a.row(3) << -l2 * l2, -4.0 * l2 * lambda, -6.0 * l2, -4.0 * lambda;
  b = Eigen::VectorXd::Zero(4);
  b(3) = l2 * l2;
}

}  // namespace hsa::control::identification
