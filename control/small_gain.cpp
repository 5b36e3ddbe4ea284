#include "control/small_gain.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

namespace hsa::control {

namespace {

using Complex = std::complex<double>;

Complex polynomial(const std::array<double, 4>& c, Complex s) { return ((c[0] * s + c[1]) * s + c[2]) * s + c[3]; }

// |W1(jω)·T0(jω)| with the gains in the plant's units (per mm).
double weighted_t0(const UncertaintyModel& m, double kp_mm, double ki_mm, double omega) {
  const Complex s(0.0, omega);
  const CylinderPlant& p = m.nominal;
  const Complex loop = (kp_mm + ki_mm / s) * p.gain / (s * (s * s + p.b1 * s + p.b0));
  return std::abs(polynomial(m.w1.num, s) / polynomial(m.w1.den, s) * loop / (1.0 + loop));
}

}  // namespace

double weight_magnitude(const CubicWeight& w, double omega_rad_s) {
  const Complex s(0.0, omega_rad_s);
  return std::abs(polynomial(w.num, s) / polynomial(w.den, s));
}

SmallGainResult weighted_complementary_sensitivity(const UncertaintyModel& model, const PiGainsSi& gains) {
  SmallGainResult r;
  // Refuses what loop_analysis refuses (gains, plant), and says whether K stabilizes P0.
  r.nominal_stable = closed_loop_poles(model.nominal, gains).front().real() < 0.0;
  if (!r.nominal_stable) {
    r.norm = std::numeric_limits<double>::quiet_NaN();
    r.peak_rad_s = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  const double kp = gains.kp * kMetresPerMillimetre;
  const double ki = gains.ki * kMetresPerMillimetre;
  const auto f = [&](double log_w) { return weighted_t0(model, kp, ki, std::pow(10.0, log_w)); };

  // 250 points a decade (0.9 % apart) over 1e-3 .. 1e5 rad/s: far wider than the loop's
  // crossover (tens of rad/s) and the weight's corners; |W1·T0| tends to |W1(0)| below and to 0
  // above. A stabilized loop's resonance is no narrower than the grid's spacing unless it is
  // nearly unstable, which the gain gate refuses on its margins first.
  constexpr double kLogMin = -3.0;
  constexpr double kLogMax = 5.0;
  constexpr int kPoints = 2000;
  const double step = (kLogMax - kLogMin) / kPoints;
  int best = 0;
  double best_value = f(kLogMin);
  for (int k = 1; k <= kPoints; ++k) {
    const double v = f(kLogMin + k * step);
    if (v > best_value) {
      best_value = v;
      best = k;
    }
  }
  // Golden section on the two intervals around the largest sample.
  double a = kLogMin + std::max(best - 1, 0) * step;
  double b = kLogMin + std::min(best + 1, kPoints) * step;
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double c = b - ratio * (b - a);
  double d = a + ratio * (b - a);
  double fc = f(c);
  double fd = f(d);
  for (int i = 0; i < 60; ++i) {
    if (fc > fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - ratio * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + ratio * (b - a);
      fd = f(d);
    }
  }
  const double refined = 0.5 * (a + b);
  const double refined_value = f(refined);
  r.norm = std::max(best_value, refined_value);
  r.peak_rad_s = std::pow(10.0, refined_value >= best_value ? refined : kLogMin + best * step);
  return r;
}

}  // namespace hsa::control
