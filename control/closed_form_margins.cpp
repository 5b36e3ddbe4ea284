#include "control/closed_form_margins.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

namespace hsa::control {

StabilityMargins closed_form_margins(const CylinderPlant& plant, const PiGainsSi& gains) {
  if (!(gains.kp > 0.0) || !(gains.ki >= 0.0) || !std::isfinite(gains.kp) || !std::isfinite(gains.ki))
    throw std::invalid_argument("loop analysis: need finite gains with kp > 0 and ki >= 0");
  if (!(plant.gain > 0.0 && plant.b1 > 0.0 && plant.b0 > 0.0))
    throw std::invalid_argument("loop analysis: plant coefficients must be > 0");
  const double kp = gains.kp * kMetresPerMillimetre;
  const double ki = gains.ki * kMetresPerMillimetre;
  const double g = plant.gain, b1 = plant.b1, b0 = plant.b0;
  const auto magnitude_db = [&](double w) {
    return 20.0 * std::log10(std::hypot(ki, kp * w) / w * g / (w * std::hypot(b0 - w * w, b1 * w)));
  };
  const auto phase = [&](double w) {
    return std::atan2(kp * w, ki) - std::numbers::pi - std::atan2(b1 * w, b0 - w * w);
  };

  StabilityMargins m{.gain_margin_db = std::numeric_limits<double>::infinity(),
                     .phase_crossover_rad_s = std::numeric_limits<double>::quiet_NaN(),
                     .phase_margin_deg = std::numeric_limits<double>::quiet_NaN(),
                     .crossover_rad_s = std::numeric_limits<double>::quiet_NaN()};
  if (const double x = b0 - ki * b1 / kp; x > 0.0) {
    m.phase_crossover_rad_s = std::sqrt(x);
    m.gain_margin_db = -magnitude_db(m.phase_crossover_rad_s);
  }

  // x⁴ + c3·x³ + c2·x² + c1·x + c0 = 0, x = ω².
  const double c[4] = {-g * g * ki * ki, -g * g * kp * kp, b0 * b0, b1 * b1 - 2.0 * b0};
  Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
  companion.bottomLeftCorner<3, 3>().setIdentity();
  for (int j = 0; j < 4; ++j) companion(j, 3) = -c[j];
  const Eigen::Vector4cd roots = companion.eigenvalues();
  const auto poly = [&](double x) { return (((x + c[3]) * x + c[2]) * x + c[1]) * x + c[0]; };
  const auto slope = [&](double x) { return ((4.0 * x + 3.0 * c[3]) * x + 2.0 * c[2]) * x + c[1]; };
  for (const std::complex<double>& r : roots) {
    if (!(r.real() > 0.0) || std::abs(r.imag()) > 1e-6 * std::abs(r)) continue;
    double x = r.real();
    for (int i = 0; i < 8; ++i) {
      const double d = slope(x);
      if (d == 0.0) break;
      const double next = x - poly(x) / d;
      if (!(next > 0.0)) break;
      x = next;
    }
    const double w = std::sqrt(x);
    const double pm = 180.0 + phase(w) * 180.0 / std::numbers::pi;
    if (std::isnan(m.phase_margin_deg) || pm < m.phase_margin_deg) {
      m.phase_margin_deg = pm;
      m.crossover_rad_s = w;
    }
  }
  return m;
}

}  // namespace hsa::control
