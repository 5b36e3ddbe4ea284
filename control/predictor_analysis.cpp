#include "control/predictor_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

namespace hsa::control {

namespace {

std::complex<double> unit_circle(double frequency_hz, double period_s) {
  return std::polar(1.0, 2.0 * std::numbers::pi * frequency_hz * period_s);
}

}  // namespace

std::complex<double> position_response(const PredictorGains& gains, double frequency_hz, double period_s) {
  const Eigen::Matrix4cd z_minus_a =
      unit_circle(frequency_hz, period_s) * Eigen::Matrix4cd::Identity() -
      predictor_state_matrix(gains).cast<std::complex<double>>();
  const Eigen::Vector4cd l = predictor_input_vector(gains).cast<std::complex<double>>();
  return z_minus_a.partialPivLu().solve(l)(0);
}

std::complex<double> position_response_eq23(const PredictorCoefficients& c, double frequency_hz,
                                            double period_s) {
  const std::complex<double> s = unit_circle(frequency_hz, period_s) - 1.0;
  const std::complex<double> numerator = (c.c2 * s + c.c1) * s + c.c0;
  return numerator / ((((s + c.c3) * s + c.c2) * s + c.c1) * s + c.c0);
}

PredictorAnalysis analyze_predictor(const std::array<double, 4>& gamma, double period_s, double l_d) {
  if (!(period_s > 0.0)) throw std::invalid_argument("predictor analysis: period must be > 0");
  PredictorAnalysis r;
  r.coefficients = predictor_coefficients(gamma);
  r.gains = predictor_gains(gamma, l_d);

  const Eigen::EigenSolver<Eigen::Matrix4d> solver(predictor_state_matrix(r.gains), false);
  const Eigen::Vector4cd ev = solver.eigenvalues();
  std::copy(ev.data(), ev.data() + 4, r.eigenvalues.begin());
  std::sort(r.eigenvalues.begin(), r.eigenvalues.end(),
            [](auto a, auto b) { return a.real() != b.real() ? a.real() > b.real() : a.imag() > b.imag(); });

  const auto magnitude = [&](double f) { return std::abs(position_response(r.gains, f, period_s)); };
  const double nyquist = 0.5 / period_s;
  constexpr int kPoints = 5000;  // 1 Hz apart at T = 0.1 ms
  const double df = nyquist / kPoints;

  int best = 1;
  for (int k = 2; k < kPoints; ++k) {
    if (magnitude(k * df) > magnitude(best * df)) best = k;
  }
  // Golden-section search on the grid cell either side of the largest sample.
  double a = (best - 1) * df;
  double b = std::min(best + 1, kPoints) * df;
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 100 && b - a > 1e-9 * nyquist; ++i) {
    const double x1 = b - ratio * (b - a);
    const double x2 = a + ratio * (b - a);
    if (magnitude(x1) < magnitude(x2)) a = x1; else b = x2;
  }
  r.peak_hz = 0.5 * (a + b);
  r.peak_magnitude = magnitude(r.peak_hz);

  const double half_power = 1.0 / std::numbers::sqrt2;
  r.minus_3db_hz = std::numeric_limits<double>::quiet_NaN();
  double lo = r.peak_hz;
  for (int k = static_cast<int>(r.peak_hz / df) + 1; k <= kPoints; ++k) {
    double hi = k * df;
    if (magnitude(hi) < half_power) {
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (magnitude(mid) < half_power) hi = mid; else lo = mid;
      }
      r.minus_3db_hz = 0.5 * (lo + hi);
      break;
    }
    lo = hi;
  }
  return r;
}

}  // namespace hsa::control
