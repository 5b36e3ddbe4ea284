#include "control/identification/valve_equation_error.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "control/identification/sampled_lti.hpp"

namespace hsa::control::identification {
namespace {

using Row = Eigen::Matrix<double, 5, 1>;
using Vec4 = Eigen::Vector4d;
using Vec5 = Eigen::Matrix<double, 5, 1>;

struct Fit {
  double rss = std::numeric_limits<double>::infinity();
  Row theta = Row::Zero();
  double width = 0.0;
  int delay = 0;
};

std::vector<double> play(const std::vector<double>& current, double width) {
  std::vector<double> p(current.size());
  double state = std::max(0.0, current.front() - 0.5 * width);
  for (std::size_t k = 0; k < current.size(); ++k) {
    state = std::clamp(state, current[k] - width, current[k]);
    p[k] = state;
  }
  return p;
}

}  // namespace

ValveModel fit_valve_equation_error(const std::vector<double>& current_a, const std::vector<double>& spool_m,
                                    const std::vector<bool>& use, double period_s,
                                    const EquationErrorOptions& options) {
  const std::size_t n = spool_m.size();
  const double lambda = options.filter_rad_s;
  const double tau_s = 1.0 / (2.0 * std::numbers::pi * options.sensor_bandwidth_hz);
  const auto skip = static_cast<std::size_t>(std::ceil((10.0 / lambda + 10.0 * tau_s) / period_s)) +
                    static_cast<std::size_t>(options.max_delay_samples);
  if (current_a.size() != n || use.size() != n || n < 2 * skip + 100)
    throw std::invalid_argument("valve equation error: the record is too short for the filters");

  Eigen::MatrixXd af;
  Eigen::VectorXd bf;
  fourth_order_filter(lambda, af, bf);
  // y: the filter alone, first-order hold.
  const SmoothInputSampling smooth = sample_smooth(af, bf, period_s);
  std::vector<Vec4> y(n);
  {
    Vec4 x = Vec4::Zero();
    x(0) = spool_m.front();
    for (std::size_t k = 0; k < n; ++k) {
      y[k] = x;
      const double slope = k + 1 < n ? (spool_m[k + 1] - spool_m[k]) / period_s : 0.0;
      x = smooth.phi * x + smooth.gamma0 * spool_m[k] + smooth.gamma1 * slope;
    }
  }
  // p: the LVDT's lag, then the filter (state 0 the lag, 1…4 the filter's), zero-order hold.
  Eigen::MatrixXd ap = Eigen::MatrixXd::Zero(5, 5);
  ap(0, 0) = -1.0 / tau_s;
  ap.bottomRightCorner(4, 4) = af;
  ap.block(1, 0, 4, 1) = bf;
  Eigen::VectorXd bp = Eigen::VectorXd::Zero(5);
  bp(0) = 1.0 / tau_s;
  const HeldInputSampling held = sample_held(ap, bp, period_s, 0.0);
  const Eigen::Matrix<double, 5, 5> phi = held.phi;
  const Vec5 gamma = held.gamma_now;

  Fit best;
  const int widths = static_cast<int>(std::floor(options.max_width_a / options.width_step_a + 1e-9));
  std::vector<double> filtered(n);
  for (int i = 0; i <= widths; ++i) {
    const double width = i * options.width_step_a;
    const std::vector<double> p = play(current_a, width);
    Vec5 x = Vec5::Zero();
    x(0) = p.front();
    x(1) = p.front();
    for (std::size_t k = 0; k < n; ++k) {
      filtered[k] = x(1);
      x = phi * x + gamma * p[k];
    }
    for (int d = 0; d <= options.max_delay_samples; ++d) {
      Eigen::Matrix<double, 5, 5> ata = Eigen::Matrix<double, 5, 5>::Zero();
      Row atb = Row::Zero();
      double btb = 0.0;
      for (std::size_t k = skip; k < n; ++k) {
        if (!use[k]) continue;
        const Row row(-y[k](3), -y[k](2), -y[k](1), filtered[k - static_cast<std::size_t>(d)], 1.0);
        ata.noalias() += row * row.transpose();
        atb += row * y[k](0);
        btb += y[k](0) * y[k](0);
      }
      const Row theta = ata.ldlt().solve(atb);
      const double rss = btb - theta.dot(atb);
      if (rss < best.rss && theta(0) > 0.0 && theta(1) > 0.0 && theta(2) > 0.0 && theta(3) > 0.0)
        best = {rss, theta, width, d};
    }
  }
  if (!std::isfinite(best.rss))
    throw std::invalid_argument("valve equation error: no dead band and delay gave a stable, positive model");

  // Roots of a3·s³ + a2·s² + a1·s + 1 from the monic companion matrix.
  const double a3 = best.theta(0);
  Eigen::Matrix3d companion = Eigen::Matrix3d::Zero();
  companion(1, 0) = 1.0;
  companion(2, 1) = 1.0;
  companion(0, 2) = -1.0 / a3;
  companion(1, 2) = -best.theta(2) / a3;
  companion(2, 2) = -best.theta(1) / a3;
  const Eigen::Vector3cd roots = companion.eigenvalues();
  int real = 0;  // the root closest to the real axis is the lag's
  for (int i = 1; i < 3; ++i)
    if (std::abs(roots(i).imag()) < std::abs(roots(real).imag())) real = i;
  std::complex<double> pair[2];
  for (int i = 0, j = 0; i < 3; ++i)
    if (i != real) pair[j++] = roots(i);
  const double w2 = (pair[0] * pair[1]).real();
  const double two_zeta_w = -(pair[0] + pair[1]).real();
  if (!(roots(real).real() < 0.0) || !(w2 > 0.0) || !(two_zeta_w > 0.0))
    throw std::invalid_argument("valve equation error: the fitted dynamics are not stable");

  ValveModel m;
  m.width_a = best.width;
  m.magnetic_lag_s = -1.0 / roots(real).real();
  m.natural_frequency_hz = std::sqrt(w2) / (2.0 * std::numbers::pi);
  m.damping_ratio = two_zeta_w / (2.0 * std::sqrt(w2));
  m.gain_m_per_a = best.theta(3);
  m.rest_position_m = best.theta(4);
  m.friction_band_m = 0.0;
  m.stroke_max_m = std::numeric_limits<double>::infinity();
  m.delay_s = best.delay * period_s;
  m.sensor_bandwidth_hz = options.sensor_bandwidth_hz;
  return m;
}

}  // namespace hsa::control::identification
