#include "control/loop_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

namespace hsa::control {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// PI gains in the plant's units (opening per mm).
struct PiGainsMm {
  double kp;
  double ki;
};

PiGainsMm to_plant_units(const CylinderPlant& plant, const PiGainsSi& gains) {
  if (!(gains.kp > 0.0) || !(gains.ki >= 0.0) || !std::isfinite(gains.kp) || !std::isfinite(gains.ki))
    throw std::invalid_argument("loop analysis: need finite gains with kp > 0 and ki >= 0");
  if (!(plant.gain > 0.0 && plant.b1 > 0.0 && plant.b0 > 0.0))
    throw std::invalid_argument("loop analysis: plant coefficients must be > 0");
  return {gains.kp * kMetresPerMillimetre, gains.ki * kMetresPerMillimetre};
}

// Closed loop T(s) = num(s)/den(s), coefficients in descending powers, den monic. With ki = 0
// the common factor s of numerator and denominator is cancelled, leaving a third-order loop.
struct TransferFunction {
  std::vector<double> num;
  std::vector<double> den;
};

TransferFunction closed_loop(const CylinderPlant& plant, const PiGainsMm& g) {
  const double n = plant.gain;
  if (g.ki == 0.0) return {{n * g.kp}, {1.0, plant.b1, plant.b0, n * g.kp}};
  return {{n * g.kp, n * g.ki}, {1.0, plant.b1, plant.b0, n * g.kp, n * g.ki}};
}

// Controllable canonical form: the state is (ξ, ξ', …, ξ⁽ⁿ⁻¹⁾) with den(d/dt)·ξ = u.
Eigen::MatrixXd companion(const std::vector<double>& den) {
  const auto n = static_cast<Eigen::Index>(den.size()) - 1;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  a.topRightCorner(n - 1, n - 1).setIdentity();
  for (Eigen::Index j = 0; j < n; ++j) a(n - 1, j) = -den[static_cast<std::size_t>(n - j)];
  return a;
}

std::vector<std::complex<double>> poles_of(const TransferFunction& t) {
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(companion(t.den), /*computeEigenvectors=*/false);
  const Eigen::VectorXcd ev = solver.eigenvalues();
  std::vector<std::complex<double>> poles(ev.data(), ev.data() + ev.size());
  std::sort(poles.begin(), poles.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() > b.real() : a.imag() > b.imag();
  });
  return poles;
}

// The positive real roots of the monic polynomial `coefficients` (descending powers), each
// polished by Newton's method on the polynomial itself.
std::vector<double> positive_real_roots(const std::vector<double>& coefficients) {
  const auto value_and_slope = [&](double x) {
    double p = 0.0, dp = 0.0;
    for (double c : coefficients) {
      dp = dp * x + p;
      p = p * x + c;
    }
    return std::pair{p, dp};
  };
  std::vector<double> roots;
  for (const std::complex<double>& r : poles_of({{1.0}, coefficients})) {
    if (!(r.real() > 0.0) || std::abs(r.imag()) > 1e-6 * std::abs(r)) continue;
    // The eigenvalues of a companion matrix with coefficients this far apart (1 to 1e12) can be
    // off by a part in 1e3; Newton's steps on the polynomial itself take them to its roots.
    double x = r.real();
    for (int i = 0; i < 8; ++i) {
      const auto [p, dp] = value_and_slope(x);
      if (dp == 0.0) break;
      const double next = x - p / dp;
      if (!(next > 0.0)) break;
      x = next;
    }
    roots.push_back(x);
  }
  return roots;
}

}  // namespace

std::vector<std::complex<double>> closed_loop_poles(const CylinderPlant& plant, const PiGainsSi& gains) {
  return poles_of(closed_loop(plant, to_plant_units(plant, gains)));
}

StabilityMargins stability_margins(const CylinderPlant& plant, const PiGainsSi& gains) {
  const PiGainsMm g = to_plant_units(plant, gains);
  const auto log_magnitude = [&](double w) {
    const double controller = std::hypot(g.ki, g.kp * w) / w;
    const double loop = plant.gain / (w * std::hypot(plant.b0 - w * w, plant.b1 * w));
    return std::log(controller * loop);
  };
  const auto phase = [&](double w) {
    return std::atan2(g.kp * w, g.ki) - std::numbers::pi - std::atan2(plant.b1 * w, plant.b0 - w * w);
  };

  StabilityMargins m{.gain_margin_db = std::numeric_limits<double>::infinity(),
                     .phase_crossover_rad_s = kNaN,
                     .phase_margin_deg = kNaN,
                     .crossover_rad_s = kNaN};
  // In closed form, with x = ω² and n the plant's gain:
  // - gain crossovers, |L(jω)| = 1:  n²·(Ki² + Kp²·x) = x²·((b0 − x)² + b1²·x), the quartic
  //     x⁴ − (2·b0 − b1²)·x³ + b0²·x² − n²·Kp²·x − n²·Ki² = 0, whose positive roots are taken;
  // - the phase crossover, arg L(jω) = −π: the vectors (Ki, Kp·ω) and (b0 − ω², b1·ω) are
  //     parallel, Kp·ω² = Kp·b0 − Ki·b1, one crossing when b0 > Ki·b1/Kp and none otherwise.
  // Several gain crossovers are possible in principle; the margin is the one nearest to
  // instability.
  const double n2 = plant.gain * plant.gain;
  for (double x : positive_real_roots({1.0, -(2.0 * plant.b0 - plant.b1 * plant.b1), plant.b0 * plant.b0,
                                       -n2 * g.kp * g.kp, -n2 * g.ki * g.ki})) {
    const double w = std::sqrt(x);
    const double pm = 180.0 + phase(w) * 180.0 / std::numbers::pi;
    if (std::isnan(m.phase_margin_deg) || pm < m.phase_margin_deg) {
      m.phase_margin_deg = pm;
      m.crossover_rad_s = w;
    }
  }
  const double phase_crossover_x = plant.b0 - g.ki * plant.b1 / g.kp;
  if (phase_crossover_x > 0.0) {
    m.phase_crossover_rad_s = std::sqrt(phase_crossover_x);
    m.gain_margin_db = -20.0 * log_magnitude(m.phase_crossover_rad_s) / std::numbers::ln10;
  }
  return m;
}

namespace {

// The step response of t, sampled exactly (zero-order hold of a step is exact) at `samples`
// points over 20 time constants of its slowest pole; nothing when t is not stable.
struct SampledResponse {
  double h = 0.0;         // s between samples; sample k is at (k + 1)·h
  std::vector<double> y;
};

// The step response of t at k·h, k = 1 … samples (stable or not: the caller decides).
SampledResponse sampled_step_at(const TransferFunction& t, double h, int samples) {
  SampledResponse r{.h = h, .y = {}};

  const auto n = static_cast<Eigen::Index>(t.den.size()) - 1;
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(n + 1, n + 1);
  augmented.topLeftCorner(n, n) = companion(t.den) * r.h;
  augmented(n - 1, n) = r.h;  // B = e_n
  const Eigen::MatrixXd e = augmented.exp();
  const Eigen::MatrixXd phi = e.topLeftCorner(n, n);
  const Eigen::VectorXd gamma = e.topRightCorner(n, 1);
  Eigen::RowVectorXd c = Eigen::RowVectorXd::Zero(n);
  for (std::size_t j = 0; j < t.num.size(); ++j) c(static_cast<Eigen::Index>(j)) = t.num[t.num.size() - 1 - j];

  r.y.reserve(static_cast<std::size_t>(samples));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  for (int k = 1; k <= samples; ++k) {
    x = phi * x + gamma;
    r.y.push_back(c.dot(x));
  }
  return r;
}

std::optional<SampledResponse> sampled_step(const TransferFunction& t, int samples) {
  const std::vector<std::complex<double>> poles = poles_of(t);
  const double slowest_decay = -poles.front().real();
  if (!(slowest_decay > 0.0)) return std::nullopt;
  // 20 time constants of the slowest pole leave e⁻²⁰ ≈ 2e-9 of any mode, far inside the band.
  const double horizon = 20.0 / slowest_decay;
  return sampled_step_at(t, horizon / samples, samples);
}

// The last time |y − target| leaves the band, interpolated between samples (y(0) = 0 counts as
// outside when the target is not 0); NaN when still outside at the horizon.
double last_exit(const SampledResponse& r, double target, double band) {
  double settling = 0.0;
  double previous_excess = std::abs(target) - band;
  for (std::size_t k = 0; k < r.y.size(); ++k) {
    const double excess = std::abs(r.y[k] - target) - band;
    if (previous_excess > 0.0 && excess <= 0.0) {
      settling = static_cast<double>(k + 1) * r.h - r.h * excess / (excess - previous_excess);
    }
    previous_excess = excess;
  }
  return previous_excess > 0.0 ? kNaN : settling;
}

}  // namespace

StepMetrics step_metrics(const CylinderPlant& plant, const PiGainsSi& gains, int samples) {
  const TransferFunction t = closed_loop(plant, to_plant_units(plant, gains));
  const std::optional<SampledResponse> r = sampled_step(t, samples);
  if (!r) return {kNaN, kNaN, kNaN};
  const double final_value = t.num.back() / t.den.back();
  double peak = 0.0;
  double peak_time = 0.0;
  for (std::size_t k = 0; k < r->y.size(); ++k) {
    if (r->y[k] > peak) {
      peak = r->y[k];
      peak_time = static_cast<double>(k + 1) * r->h;
    }
  }
  return {.overshoot_pct = std::max(0.0, (peak - final_value) / final_value * 100.0),
          .peak_time_s = peak_time,
          .settling_s = last_exit(*r, final_value, 0.02 * std::abs(final_value))};
}

std::vector<double> step_response(const CylinderPlant& plant, const PiGainsSi& gains, double period_s, int samples) {
  if (!(period_s > 0.0) || samples < 0) throw std::invalid_argument("step_response: period must be > 0, samples >= 0");
  const TransferFunction t = closed_loop(plant, to_plant_units(plant, gains));
  return sampled_step_at(t, period_s, samples).y;
}

DisturbanceMetrics disturbance_response(const CylinderPlant& plant, const PiGainsSi& gains, int samples) {
  const PiGainsMm g = to_plant_units(plant, gains);
  // Y/D = P/(1 + K·P) = n·s / (s⁴ + b1·s³ + b0·s² + n·Kp·s + n·Ki), answering a step D. With
  // Ki = 0 the denominator has a root at 0: the offset never goes away, and sampled_step says
  // unstable.
  const double n = plant.gain;
  const TransferFunction t{{n, 0.0}, {1.0, plant.b1, plant.b0, n * g.kp, n * g.ki}};
  const std::optional<SampledResponse> r = sampled_step(t, samples);
  if (!r) return {kNaN, kNaN};
  double peak = 0.0;
  for (double y : r->y) peak = std::max(peak, std::abs(y));
  return {.peak_mm = peak, .recovery_s = last_exit(*r, 0.0, 0.02 * peak)};
}

LoopAnalysis analyze_loop(const CylinderPlant& plant, const PiGainsSi& gains) {
  LoopAnalysis a;
  a.poles = closed_loop_poles(plant, gains);
  a.stable = a.poles.front().real() < 0.0;
  a.margins = stability_margins(plant, gains);
  a.step = step_metrics(plant, gains);
  return a;
}

}  // namespace hsa::control
