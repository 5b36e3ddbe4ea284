#include "control/valve_predictive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace hsa::control {

ValvePredictiveLaw::ValvePredictiveLaw(const ValvePredictiveParams& params) : p_(params) {
  if (!p_.enabled) throw std::invalid_argument("ValvePredictiveLaw: the law is not enabled");
  if (!(p_.period_s > 0.0) || p_.delay_samples < 1 || p_.preview_samples < 1 || p_.horizon_samples < 1)
    throw std::invalid_argument("ValvePredictiveLaw: T must be > 0, D, P and H >= 1");
  if (p_.reference_window_samples < 1 || p_.reference_window_samples > kMaxReferenceWindow)
    throw std::invalid_argument("ValvePredictiveLaw: the reference's window W must lie in [1, " +
                                std::to_string(kMaxReferenceWindow) + "] samples");
  if (!(p_.held_band_m >= 0.0))
    throw std::invalid_argument("ValvePredictiveLaw: the held reference's band must be >= 0");
  if (!(p_.lower_a < p_.upper_a) || !(p_.current_max_a > 0.0) || !(p_.direction_velocity_m_s > 0.0) ||
      !(p_.gain_m_per_a > 0.0) || p_.dither_half_period_samples < 0 || p_.max_qp_iterations < 1)
    throw std::invalid_argument("ValvePredictiveLaw: the box, I_max, v_d, g or the QP's iteration limit is not valid");
  np_ = kValvePredictiveFixedStates + p_.delay_samples;
  P_ = p_.preview_samples;
  n_ = np_ + 2 * (P_ + 1);
  h_ = p_.horizon_samples;
  const auto size = [](const std::vector<double>& v) { return static_cast<long>(v.size()); };
  if (size(p_.transition) != long{np_} * np_ || size(p_.input) != np_ || size(p_.friction) != np_ ||
      size(p_.kalman_gain) != np_ || (!p_.held_kalman_gain.empty() && size(p_.held_kalman_gain) != np_) ||
      size(p_.qp_hessian) != long{h_} * h_ || size(p_.qp_linear) != long{h_} * n_)
    throw std::invalid_argument("ValvePredictiveLaw: the matrices' sizes do not match D, P and H");
  z_.assign(static_cast<std::size_t>(np_), 0.0);
  window_.assign(static_cast<std::size_t>(p_.reference_window_samples), 0.0);
  znext_ = z_;
  x0_.assign(static_cast<std::size_t>(n_), 0.0);
  gradient_.assign(static_cast<std::size_t>(h_), 0.0);
  u_ = gradient_;
  u_free_ = gradient_;
  rhs_ = gradient_;
  multiplier_ = gradient_;
  bound_.assign(static_cast<std::size_t>(h_), 0);
  // H⁻¹ and −H⁻¹·F for the range-space steps of solve_qp().
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> hessian_map(p_.qp_hessian.data(), h_, h_);
  const Eigen::LLT<Eigen::MatrixXd> llt(hessian_map);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument("ValvePredictiveLaw: the QP's Hessian is not positive definite");
  RowMajor inv = llt.solve(Eigen::MatrixXd::Identity(h_, h_));
  inv = 0.5 * (inv + inv.transpose()).eval();
  RowMajor unconstrained = -(inv * Eigen::Map<const RowMajor>(p_.qp_linear.data(), h_, n_));
  inverse_.assign(inv.data(), inv.data() + inv.size());
  unconstrained_.assign(unconstrained.data(), unconstrained.data() + unconstrained.size());
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
  std::fill(window_.begin(), window_.end(), reference_m);
  window_head_ = 0;
  std::fill(x0_.begin() + np_ + P_ + 1, x0_.end(), 0.0);
  std::fill(active_.begin(), active_.end(), 0);
  held_a_ = force + p_.mean_play_a;
  saturated_ = false;
  dither_phase_ = 0;
  started_ = true;
}

void ValvePredictiveLaw::advance_reference(double reference_m) noexcept {
  // The reference register: r(i − P) … r(i), each the mean of the last W references given. A
  // reference held over W samples and then stepped (the cylinder loop's opening, in a cascade)
  // becomes the line through its steps: a step in one sample is a target no spool can follow,
  // and the QP's answer to it, a pulse of current every W samples, left the spool tens of µm
  // behind a slow motion (docs/valve-loop.md, "In the cascade").
  double* xi = x0_.data() + np_;
  for (int j = 0; j < P_; ++j) xi[j] = xi[j + 1];
  window_[window_head_] = reference_m;
  if (++window_head_ == window_.size()) window_head_ = 0;
  double sum = 0.0;
  for (double v : window_) sum += v;
  xi[P_] = sum / static_cast<double>(window_.size());
  // The friction's sign along the target, φ(j) = tanh((ξ(j+1) − ξ(j))/(T·v_d)), shifts with ξ: only
  // the newest is computed, and the last one is held.
  double* phi = xi + P_ + 1;
  for (int j = 0; j + 1 < P_; ++j) phi[j] = phi[j + 1];
  phi[P_ - 1] = std::tanh((xi[P_] - xi[P_ - 1]) * (1.0 / (p_.period_s * p_.direction_velocity_m_s)));
  phi[P_] = phi[P_ - 1];
}

void ValvePredictiveLaw::predict(double command_a) noexcept {
  // The model one sample on, with the command as applied (the dither's mean is in the play's).
  const double phi = x0_[static_cast<std::size_t>(np_ + P_ + 1)];
  for (int r = 0; r < np_; ++r) {
    double s = p_.input[static_cast<std::size_t>(r)] * command_a + p_.friction[static_cast<std::size_t>(r)] * phi;
    const double* row = p_.transition.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(np_);
    for (int c = 0; c < np_; ++c) s += row[c] * z_[static_cast<std::size_t>(c)];
    znext_[static_cast<std::size_t>(r)] = s;
  }
  z_.swap(znext_);
  if (p_.dither_half_period_samples > 0 && ++dither_phase_ == 2 * static_cast<std::uint32_t>(p_.dither_half_period_samples))
    dither_phase_ = 0;
}

double ValvePredictiveLaw::update(double reference_m, double measured_m, std::uint64_t elapsed) noexcept {
  if (!started_) reset(measured_m, reference_m);
  if (elapsed > 1) [[unlikely]] {
    // The missed periods: the drive held the last command, and no reading came; the reference
    // they would have brought is taken as this one.
    const std::uint64_t missed = std::min<std::uint64_t>(elapsed - 1, kMaxCatchUp);
    for (std::uint64_t i = 0; i < missed; ++i) {
      advance_reference(reference_m);
      predict(held_a_);
    }
  }
  advance_reference(reference_m);
  // The Kalman correction with this reading.
  const double innovation = measured_m - z_[kReading];
  // While the target is held (it moved less than the band over the preview) the disturbance is
  // estimated with the faster gain: nothing then tells the friction's sign, and what holds the
  // spool off its target must come out of the disturbance within the cylinder loop's time.
  const double* xi = x0_.data() + np_;
  const bool held = !p_.held_kalman_gain.empty() && std::abs(xi[P_] - xi[0]) <= p_.held_band_m;
  const std::vector<double>& gain = held ? p_.held_kalman_gain : p_.kalman_gain;
  for (int j = 0; j < np_; ++j) z_[static_cast<std::size_t>(j)] += gain[static_cast<std::size_t>(j)] * innovation;
  z_[kOne] = 1.0;
  std::copy(z_.begin(), z_.end(), x0_.begin());

  held_a_ = solve_qp();
  saturated_ = !(u_[0] > p_.lower_a && u_[0] < p_.upper_a);
  double out = held_a_;
  if (p_.dither_half_period_samples > 0)
    out += dither_phase_ < static_cast<std::uint32_t>(p_.dither_half_period_samples) ? p_.dither_amplitude_a
                                                                                       : -p_.dither_amplitude_a;
  predict(held_a_);
  return std::clamp(out, 0.0, p_.current_max_a);
}

namespace {

// a·x = b in place for the m × m symmetric positive definite a, its lower triangle read from rows
// of `stride` and overwritten by its Cholesky factor; b is overwritten by x.
void cholesky_solve(double* a, int stride, int m, double* b) noexcept {
  const auto at = [&](int r, int c) -> double& { return a[static_cast<std::size_t>(r) * static_cast<std::size_t>(stride) + static_cast<std::size_t>(c)]; };
  for (int j = 0; j < m; ++j) {
    double d = at(j, j);
    for (int k = 0; k < j; ++k) d -= at(j, k) * at(j, k);
    d = std::sqrt(std::max(d, 1e-300));
    at(j, j) = d;
    for (int i = j + 1; i < m; ++i) {
      double s = at(i, j);
      for (int k = 0; k < j; ++k) s -= at(i, k) * at(j, k);
      at(i, j) = s / d;
    }
  }
  for (int i = 0; i < m; ++i) {  // L·w = b
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= at(i, k) * b[k];
    b[i] = s / at(i, i);
  }
  for (int i = m - 1; i >= 0; --i) {  // Lᵀ·x = w
    double s = b[i];
    for (int k = i + 1; k < m; ++k) s -= at(k, i) * b[k];
    b[i] = s / at(i, i);
  }
}

}  // namespace

// minimise ½·UᵀHU + cᵀU, lo <= U <= hi, c = F·x0. An active-set method for a box: solve with the
// bound commands at their bounds; fix every free command that leaves the box; once none does,
// free the bound command whose multiplier says the cost falls furthest into the box; stop when
// none does. (Freeing every such command at once, block principal pivoting, was tried: on this
// Hessian, whose commands are strongly coupled, it wandered for hundreds of steps after a jump of
// the reference where this took at most a hundred.)
//
// A step is solved on whichever side is smaller, so that its cost is at most that of H/2 commands:
// - with k bound commands and k <= H − k, on the inverse (the range space): the commands with
//   none bound are U₀ = −H⁻¹·F·x0 (one product with a matrix the constructor computed), and
//   with the bound set A, U = U₀ − H⁻¹_{:,A}·μ where H⁻¹_{AA}·μ = U₀_A − b_A, μ the bounds'
//   multipliers (the cost's gradient on A is −μ). A ramp, the usual case, has no bound command
//   and costs the one product;
// - otherwise on the free commands F (the null space): H_FF·U_F = −(c_F + H_FA·b_A), and the
//   gradient c + H·U read on A.
// A sample's steps stop once the next would take the multiply-adds past kQpWorkBudget: after a
// jump of the reference, when most commands meet a bound, the method may free and bind one
// command at a time for a hundred steps, and a sample must end within the base tick. The commands
// so far, clamped to the box, are applied, and the next sample starts from their active set.
double ValvePredictiveLaw::solve_qp() noexcept {
  for (int r = 0; r < h_; ++r) {
    const double* row = unconstrained_.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(n_);
    double s = 0.0;
    for (int c = 0; c < n_; ++c) s += row[c] * x0_[static_cast<std::size_t>(c)];
    u_free_[static_cast<std::size_t>(r)] = s;
  }
  gradient_ready_ = false;
  // Warm start: last sample's active set, one sample on.
  for (int i = 0; i + 1 < h_; ++i) active_[static_cast<std::size_t>(i)] = active_[static_cast<std::size_t>(i) + 1];
  active_[static_cast<std::size_t>(h_) - 1] = 0;

  qp_iterations_ = 0;
  qp_complete_ = false;
  long work = long{h_} * n_;  // the product above
  for (int it = 0; it < p_.max_qp_iterations; ++it) {
    int m = 0, k = 0;
    for (int i = 0; i < h_; ++i) {
      if (active_[static_cast<std::size_t>(i)] == 0) free_[static_cast<std::size_t>(m++)] = i;
      else bound_[static_cast<std::size_t>(k++)] = i;
    }
    // The step's multiply-adds, over-counted: its factor, solves and products, the gradient's
    // set-up on the free side when it is not there yet, and the passes over the H commands (the
    // sides, the fixes, a command bound or freed).
    const long small = std::min(k, m);
    const long step = small * small * small / 6 + small * small + long{h_} * (small + 1) + long{k} * m +
                      (k <= m || gradient_ready_ ? 0 : long{h_} * (n_ + k)) + 4L * h_;
    if (it > 0 && work + step > kQpWorkBudget) break;
    work += step;
    ++qp_iterations_;
    active_count_ = k;
    if (k <= m) solve_bound(k);
    else solve_free();
    bool fixed = false;
    for (int a = 0; a < m; ++a) {
      const int i = free_[static_cast<std::size_t>(a)];
      if (u_[static_cast<std::size_t>(i)] < p_.lower_a) bind(i, -1), fixed = true;
      else if (u_[static_cast<std::size_t>(i)] > p_.upper_a) bind(i, 1), fixed = true;
    }
    if (fixed) continue;
    int release = -1;
    double worst = 0.0;
    for (int j = 0; j < k; ++j) {
      const int i = bound_[static_cast<std::size_t>(j)];
      // At lo the cost must not fall as the command rises (μ <= 0); at hi, as it falls (μ >= 0).
      const double mu = multiplier_[static_cast<std::size_t>(j)];
      const double into_box = active_[static_cast<std::size_t>(i)] < 0 ? mu : -mu;
      if (into_box > worst) {
        worst = into_box;
        release = i;
      }
    }
    if (release < 0) {
      qp_complete_ = true;
      break;
    }
    bind(release, 0);
  }
  qp_work_ = work;
  return std::clamp(u_[0], p_.lower_a, p_.upper_a);
}

void ValvePredictiveLaw::solve_bound(int k) noexcept {
  for (int a = 0; a < k; ++a) {
    const int ia = bound_[static_cast<std::size_t>(a)];
    multiplier_[static_cast<std::size_t>(a)] = u_free_[static_cast<std::size_t>(ia)] - bound_of(ia);
    for (int b = 0; b <= a; ++b) chol_[static_cast<std::size_t>(a * h_ + b)] = inverse(ia, bound_[static_cast<std::size_t>(b)]);
  }
  cholesky_solve(chol_.data(), h_, k, multiplier_.data());
  for (int i = 0; i < h_; ++i) {
    double s = u_free_[static_cast<std::size_t>(i)];
    const double* row = inverse_.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(h_);
    for (int a = 0; a < k; ++a) s -= row[bound_[static_cast<std::size_t>(a)]] * multiplier_[static_cast<std::size_t>(a)];
    u_[static_cast<std::size_t>(i)] = s;
  }
  for (int a = 0; a < k; ++a) u_[static_cast<std::size_t>(bound_[static_cast<std::size_t>(a)])] = bound_of(bound_[static_cast<std::size_t>(a)]);
}

// The free side keeps w = c + H·b̃ (b̃: the commands at their bounds, 0 where free) from its first
// step in a sample on, and bind() moves it with each command that changes side, so a step that
// frees or binds one command of many costs H multiply-adds rather than H per bound command.
void ValvePredictiveLaw::solve_free() noexcept {
  if (!gradient_ready_) {
    for (int r = 0; r < h_; ++r) {
      const double* row = p_.qp_linear.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(n_);
      double s = 0.0;
      for (int c = 0; c < n_; ++c) s += row[c] * x0_[static_cast<std::size_t>(c)];
      gradient_[static_cast<std::size_t>(r)] = s;
    }
    for (int i = 0; i < h_; ++i) {
      if (active_[static_cast<std::size_t>(i)] == 0) continue;
      const double b = bound_of(i);
      const double* row = p_.qp_hessian.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(h_);
      for (int r = 0; r < h_; ++r) gradient_[static_cast<std::size_t>(r)] += row[r] * b;
    }
    gradient_ready_ = true;
  }
  int m = 0;
  for (int i = 0; i < h_; ++i) {
    if (active_[static_cast<std::size_t>(i)] == 0) free_[static_cast<std::size_t>(m++)] = i;
    else u_[static_cast<std::size_t>(i)] = bound_of(i);
  }
  for (int a = 0; a < m; ++a) {
    const int fa = free_[static_cast<std::size_t>(a)];
    rhs_[static_cast<std::size_t>(a)] = -gradient_[static_cast<std::size_t>(fa)];
    for (int b = 0; b <= a; ++b) chol_[static_cast<std::size_t>(a * h_ + b)] = hessian(fa, free_[static_cast<std::size_t>(b)]);
  }
  cholesky_solve(chol_.data(), h_, m, rhs_.data());
  for (int a = 0; a < m; ++a) u_[static_cast<std::size_t>(free_[static_cast<std::size_t>(a)])] = rhs_[static_cast<std::size_t>(a)];
  int j = 0;
  for (int i = 0; i < h_; ++i) {
    if (active_[static_cast<std::size_t>(i)] == 0) continue;
    double g = gradient_[static_cast<std::size_t>(i)];
    for (int a = 0; a < m; ++a) g += hessian(i, free_[static_cast<std::size_t>(a)]) * rhs_[static_cast<std::size_t>(a)];
    multiplier_[static_cast<std::size_t>(j++)] = -g;
  }
}

void ValvePredictiveLaw::bind(int i, int side) noexcept {
  if (gradient_ready_) {
    const double before = active_[static_cast<std::size_t>(i)] == 0 ? 0.0 : bound_of(i);
    const double after = side == 0 ? 0.0 : side < 0 ? p_.lower_a : p_.upper_a;
    const double* row = p_.qp_hessian.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(h_);
    for (int r = 0; r < h_; ++r) gradient_[static_cast<std::size_t>(r)] += row[r] * (after - before);
  }
  active_[static_cast<std::size_t>(i)] = side;
}

}  // namespace hsa::control
