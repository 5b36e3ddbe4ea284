#include "control/valve_predictive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::control {

ValvePredictiveLaw::ValvePredictiveLaw(const ValvePredictiveParams& params) : p_(params) {
  if (!p_.enabled) throw std::invalid_argument("ValvePredictiveLaw: the law is not enabled");
  if (!(p_.period_s > 0.0) || p_.delay_samples < 1 || p_.preview_samples < 1 || p_.horizon_samples < 1)
    throw std::invalid_argument("ValvePredictiveLaw: T must be > 0, D, P and H >= 1");
  if (!(p_.lower_a < p_.upper_a) || !(p_.current_max_a > 0.0) || !(p_.direction_velocity_m_s > 0.0) ||
      !(p_.gain_m_per_a > 0.0) || p_.dither_half_period_samples < 0 || p_.max_qp_iterations < 1)
    throw std::invalid_argument("ValvePredictiveLaw: the box, I_max, v_d, g or the QP's iteration limit is not valid");
  np_ = kValvePredictiveFixedStates + p_.delay_samples;
  P_ = p_.preview_samples;
  n_ = np_ + 2 * (P_ + 1);
  h_ = p_.horizon_samples;
  const auto size = [](const std::vector<double>& v) { return static_cast<long>(v.size()); };
  if (size(p_.transition) != long{np_} * np_ || size(p_.input) != np_ || size(p_.friction) != np_ ||
      size(p_.kalman_gain) != np_ || size(p_.qp_hessian) != long{h_} * h_ || size(p_.qp_linear) != long{h_} * n_)
    throw std::invalid_argument("ValvePredictiveLaw: the matrices' sizes do not match D, P and H");
  z_.assign(static_cast<std::size_t>(np_), 0.0);
  znext_ = z_;
  x0_.assign(static_cast<std::size_t>(n_), 0.0);
  c_.assign(static_cast<std::size_t>(h_), 0.0);
  u_ = c_;
  rhs_ = c_;
  chol_.assign(static_cast<std::size_t>(h_) * static_cast<std::size_t>(h_), 0.0);
  active_.assign(static_cast<std::size_t>(h_), 0);
  free_.assign(static_cast<std::size_t>(h_), 0);
}

void ValvePredictiveLaw::reset(double measured_m, double reference_m) noexcept {
  std::fill(z_.begin(), z_.end(), 0.0);
  const double force = (measured_m - p_.rest_position_m) / p_.gain_m_per_a;
  z_[kForce] = force;
  z_[kPosition] = measured_m;
  z_[kReading] = measured_m;
  z_[kOne] = 1.0;
  for (int j = kValvePredictiveFixedStates; j < np_; ++j) z_[static_cast<std::size_t>(j)] = force + p_.mean_play_a;
  std::fill(x0_.begin() + np_, x0_.begin() + np_ + P_ + 1, reference_m);
  std::fill(x0_.begin() + np_ + P_ + 1, x0_.end(), 0.0);
  std::fill(active_.begin(), active_.end(), 0);
  dither_phase_ = 0;
  started_ = true;
}

double ValvePredictiveLaw::update(double reference_m, double measured_m) noexcept {
  if (!started_) reset(measured_m, reference_m);
  // The reference register: r(i − P) … r(i).
  double* xi = x0_.data() + np_;
  for (int j = 0; j < P_; ++j) xi[j] = xi[j + 1];
  xi[P_] = reference_m;
  // The friction's sign along the target, the last one held.
  double* phi = xi + P_ + 1;
  const double slope_scale = 1.0 / (p_.period_s * p_.direction_velocity_m_s);
  for (int j = 0; j < P_; ++j) phi[j] = std::tanh((xi[j + 1] - xi[j]) * slope_scale);
  phi[P_] = phi[P_ - 1];
  // The Kalman correction with this reading.
  const double innovation = measured_m - z_[kReading];
  for (int j = 0; j < np_; ++j) z_[static_cast<std::size_t>(j)] += p_.kalman_gain[static_cast<std::size_t>(j)] * innovation;
  z_[kOne] = 1.0;
  std::copy(z_.begin(), z_.end(), x0_.begin());

  const double u = solve_qp();

  // The model one sample on, with the command as applied (the dither's mean is in the play's).
  for (int r = 0; r < np_; ++r) {
    double s = p_.input[static_cast<std::size_t>(r)] * u + p_.friction[static_cast<std::size_t>(r)] * phi[0];
    const double* row = p_.transition.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(np_);
    for (int c = 0; c < np_; ++c) s += row[c] * z_[static_cast<std::size_t>(c)];
    znext_[static_cast<std::size_t>(r)] = s;
  }
  z_.swap(znext_);

  double out = u;
  if (p_.dither_half_period_samples > 0) {
    const auto half = static_cast<std::uint32_t>(p_.dither_half_period_samples);
    out += dither_phase_ < half ? p_.dither_amplitude_a : -p_.dither_amplitude_a;
    if (++dither_phase_ == 2 * half) dither_phase_ = 0;
  }
  return std::clamp(out, 0.0, p_.current_max_a);
}

// minimise ½·UᵀHU + cᵀU, lo <= U <= hi, c = F·x0. An active-set method for a box: solve on the free
// commands with the others at their bounds; fix every free command that leaves the box; once none
// does, release the bound command whose gradient points furthest into the box; stop when no
// gradient does.
double ValvePredictiveLaw::solve_qp() noexcept {
  for (int r = 0; r < h_; ++r) {
    const double* row = p_.qp_linear.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(n_);
    double s = 0.0;
    for (int c = 0; c < n_; ++c) s += row[c] * x0_[static_cast<std::size_t>(c)];
    c_[static_cast<std::size_t>(r)] = s;
  }
  // Warm start: last sample's active set, one sample on.
  for (int i = 0; i + 1 < h_; ++i) active_[static_cast<std::size_t>(i)] = active_[static_cast<std::size_t>(i) + 1];
  active_[static_cast<std::size_t>(h_) - 1] = 0;

  qp_iterations_ = 0;
  for (int it = 0; it < p_.max_qp_iterations; ++it) {
    ++qp_iterations_;
    int m = 0;
    for (int i = 0; i < h_; ++i) {
      const int a = active_[static_cast<std::size_t>(i)];
      if (a == 0) free_[static_cast<std::size_t>(m++)] = i;
      else u_[static_cast<std::size_t>(i)] = a < 0 ? p_.lower_a : p_.upper_a;
    }
    // H_ff·u_f = −(c_f + H_fa·u_a), by Cholesky in place (H is positive definite: ρ > 0).
    for (int a = 0; a < m; ++a) {
      const int fa = free_[static_cast<std::size_t>(a)];
      double r = -c_[static_cast<std::size_t>(fa)];
      for (int i = 0; i < h_; ++i)
        if (active_[static_cast<std::size_t>(i)] != 0) r -= hessian(fa, i) * u_[static_cast<std::size_t>(i)];
      rhs_[static_cast<std::size_t>(a)] = r;
      for (int b = 0; b <= a; ++b) chol_[static_cast<std::size_t>(a * h_ + b)] = hessian(fa, free_[static_cast<std::size_t>(b)]);
    }
    for (int j = 0; j < m; ++j) {
      double d = chol_[static_cast<std::size_t>(j * h_ + j)];
      for (int k = 0; k < j; ++k) d -= chol_[static_cast<std::size_t>(j * h_ + k)] * chol_[static_cast<std::size_t>(j * h_ + k)];
      d = std::sqrt(std::max(d, 1e-300));
      chol_[static_cast<std::size_t>(j * h_ + j)] = d;
      for (int i = j + 1; i < m; ++i) {
        double s = chol_[static_cast<std::size_t>(i * h_ + j)];
        for (int k = 0; k < j; ++k) s -= chol_[static_cast<std::size_t>(i * h_ + k)] * chol_[static_cast<std::size_t>(j * h_ + k)];
        chol_[static_cast<std::size_t>(i * h_ + j)] = s / d;
      }
    }
    for (int i = 0; i < m; ++i) {  // L·w = rhs
      double s = rhs_[static_cast<std::size_t>(i)];
      for (int k = 0; k < i; ++k) s -= chol_[static_cast<std::size_t>(i * h_ + k)] * rhs_[static_cast<std::size_t>(k)];
      rhs_[static_cast<std::size_t>(i)] = s / chol_[static_cast<std::size_t>(i * h_ + i)];
    }
    for (int i = m - 1; i >= 0; --i) {  // Lᵀ·u = w
      double s = rhs_[static_cast<std::size_t>(i)];
      for (int k = i + 1; k < m; ++k) s -= chol_[static_cast<std::size_t>(k * h_ + i)] * rhs_[static_cast<std::size_t>(k)];
      rhs_[static_cast<std::size_t>(i)] = s / chol_[static_cast<std::size_t>(i * h_ + i)];
      u_[static_cast<std::size_t>(free_[static_cast<std::size_t>(i)])] = rhs_[static_cast<std::size_t>(i)];
    }
    bool fixed = false;
    for (int a = 0; a < m; ++a) {
      const int i = free_[static_cast<std::size_t>(a)];
      if (u_[static_cast<std::size_t>(i)] < p_.lower_a) active_[static_cast<std::size_t>(i)] = -1, fixed = true;
      else if (u_[static_cast<std::size_t>(i)] > p_.upper_a) active_[static_cast<std::size_t>(i)] = 1, fixed = true;
    }
    if (fixed) continue;
    int release = -1;
    double worst = 0.0;
    for (int i = 0; i < h_; ++i) {
      const int a = active_[static_cast<std::size_t>(i)];
      if (a == 0) continue;
      double g = c_[static_cast<std::size_t>(i)];
      for (int k = 0; k < h_; ++k) g += hessian(i, k) * u_[static_cast<std::size_t>(k)];
      // At lo the cost must not fall as the command rises (g >= 0); at hi, as it falls (g <= 0).
      const double into_box = a < 0 ? -g : g;
      if (into_box > worst) {
        worst = into_box;
        release = i;
      }
    }
    if (release < 0) break;
    active_[static_cast<std::size_t>(release)] = 0;
  }
  for (double& v : u_) v = std::clamp(v, p_.lower_a, p_.upper_a);
  return u_[0];
}

}  // namespace hsa::control
