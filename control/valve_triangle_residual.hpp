#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace hsa::control {

// The offline valve designs' score (valve_feedback_design.hpp, valve_predictive_design.hpp): the
// experiment's 70 % triangle at 10 Hz (docs/valve-loop.md) and Canuto et al. (2014) eq 9's peak
// residual against it, taken at the pure delay that fits the readings best.

inline constexpr double kDesignTriangleAmplitudeM = 0.70 * 1.25e-3;  // 70 % of the spool's half stroke
inline constexpr double kDesignTriangleFrequencyHz = 10.0;

// The triangle of unit amplitude, 0 at t = 0 and rising.
inline double unit_triangle(double frequency_hz, double t_s) {
  const double p = t_s * frequency_hz - std::floor(t_s * frequency_hz);
  if (p < 0.25) return 4.0 * p;
  if (p < 0.75) return 2.0 - 4.0 * p;
  return 4.0 * p - 4.0;
}

// max |y(t) − r(t − τ)| at the τ on a 0.01 ms grid up to `max_delay_s` with the least squares.
inline double triangle_peak_residual(const std::vector<double>& t, const std::vector<double>& y, double max_delay_s) {
  double best = INFINITY, peak = 0.0;
  const int steps = static_cast<int>(std::lround(max_delay_s / 1e-5));
  for (int j = 0; j <= steps; ++j) {
    const double tau = j * 1e-5;
    double sum = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      const double eta = y[k] - kDesignTriangleAmplitudeM * unit_triangle(kDesignTriangleFrequencyHz, t[k] - tau);
      sum += eta * eta;
      worst = std::max(worst, std::abs(eta));
    }
    if (sum < best) {
      best = sum;
      peak = worst;
    }
  }
  return peak;
}

}  // namespace hsa::control
