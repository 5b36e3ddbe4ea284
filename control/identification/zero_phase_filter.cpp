#include "control/identification/zero_phase_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::control::identification {
namespace {

struct Biquad {
  double b0, b1, b2, a1, a2;  // normalized by a0

  // Filters x in place, starting in the steady state of x's first value (unit DC gain).
  void run(std::vector<double>& x) const {
    if (x.empty()) return;
    const double x0 = x.front();
    double s1 = 0.0, s2 = 0.0;  // transposed direct form II, on x − x0
    for (double& v : x) {
      const double in = v - x0;
      const double out = b0 * in + s1;
      s1 = b1 * in - a1 * out + s2;
      s2 = b2 * in - a2 * out;
      v = out + x0;
    }
  }
};

Biquad low_pass(double cutoff_hz, double sample_rate_hz, double q) {
  const double w0 = 2.0 * std::numbers::pi * cutoff_hz / sample_rate_hz;
  const double alpha = std::sin(w0) / (2.0 * q);
  const double c = std::cos(w0);
  const double a0 = 1.0 + alpha;
  return {(1.0 - c) / 2.0 / a0, (1.0 - c) / a0, (1.0 - c) / 2.0 / a0, -2.0 * c / a0, (1.0 - alpha) / a0};
}

}  // namespace

std::vector<double> butterworth4_zero_phase(const std::vector<double>& x, double cutoff_hz, double sample_rate_hz) {
  if (!(cutoff_hz > 0.0) || !(cutoff_hz < sample_rate_hz / 2.0))
    throw std::invalid_argument("the filter's cut-off must lie between 0 and half the sample rate");
  const Biquad stages[] = {low_pass(cutoff_hz, sample_rate_hz, 1.0 / (2.0 * std::cos(std::numbers::pi / 8.0))),
                           low_pass(cutoff_hz, sample_rate_hz, 1.0 / (2.0 * std::cos(3.0 * std::numbers::pi / 8.0)))};
  std::vector<double> y = x;
  for (const Biquad& s : stages) s.run(y);
  std::reverse(y.begin(), y.end());
  for (const Biquad& s : stages) s.run(y);
  std::reverse(y.begin(), y.end());
  return y;
}

}  // namespace hsa::control::identification
