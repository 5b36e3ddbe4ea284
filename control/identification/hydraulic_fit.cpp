#include "control/identification/hydraulic_fit.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "control/identification/sampled_lti.hpp"

namespace hsa::control::identification {
namespace {

constexpr int kParameters = 4;
using State = Eigen::Vector4d;
using Row = Eigen::Matrix<double, kParameters, 1>;

// The filter's states at every sample for a signal held over each period and delayed.
std::vector<State> filter_held(const std::vector<double>& u, const HeldInputSampling& s) {
  std::vector<State> out(u.size());
  State x = State::Zero();
  x(0) = u.front();  // at rest on the first value
  const auto at = [&](long k) { return u[static_cast<std::size_t>(std::max(0L, k))]; };
  for (std::size_t k = 0; k < u.size(); ++k) {
    out[k] = x;
    const long now = static_cast<long>(k) - s.whole_periods;
    x = s.phi * x + s.gamma_late * at(now - 1) + s.gamma_now * at(now);
  }
  return out;
}

std::vector<State> filter_smooth(const std::vector<double>& y, const SmoothInputSampling& s, double period_s) {
  std::vector<State> out(y.size());
  State x = State::Zero();
  x(0) = y.front();
  for (std::size_t k = 0; k < y.size(); ++k) {
    out[k] = x;
    const double slope = k + 1 < y.size() ? (y[k + 1] - y[k]) / period_s : 0.0;
    x = s.phi * x + s.gamma0 * y[k] + s.gamma1 * slope;
  }
  return out;
}

struct Normal {
  Eigen::Matrix<double, kParameters, kParameters> ata = decltype(ata)::Zero();
  Row atb = Row::Zero();
  double btb = 0.0;

  void add(const Row& row, double target) {
    ata.noalias() += row * row.transpose();
    atb += row * target;
    btb += target * target;
  }
  Normal& operator+=(const Normal& o) {
    ata += o.ata;
    atb += o.atb;
    btb += o.btb;
    return *this;
  }
  [[nodiscard]] Row solve() const { return ata.ldlt().solve(atb); }
  [[nodiscard]] double rss(const Row& theta) const { return std::max(0.0, btb - theta.dot(atb)); }
};

}  // namespace

HydraulicFit fit_hydraulics(const std::vector<double>& opening, const std::vector<double>& position_m,
                            const std::vector<double>& pressure_a_pa, const std::vector<double>& pressure_b_pa,
                            double period_s, const HydraulicFitOptions& options) {
  const std::size_t n = opening.size();
  if (position_m.size() != n || pressure_a_pa.size() != n || pressure_b_pa.size() != n)
    throw std::invalid_argument("hydraulic fit: the records differ in length");
  if (!(period_s > 0.0) || !(options.filter_rad_s > 0.0) || options.segments < 1 || !(options.delay_step_s > 0.0) ||
      !(options.piston_area_m2 > 0.0) || !(options.area_ratio > 0.0))
    throw std::invalid_argument("hydraulic fit: period, filter, segments, area and ratio must be positive");
  // The filter's start-up transient: 10 time constants of the 4-fold pole are skipped.
  const auto skip = static_cast<std::size_t>(std::ceil(10.0 / (options.filter_rad_s * period_s)));
  const auto segments = static_cast<std::size_t>(options.segments);
  if (n < skip * (segments + 1)) throw std::invalid_argument("hydraulic fit: the record is too short");

  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  fourth_order_filter(options.filter_rad_s, a, b);
  std::vector<double> y_mm(n), force(n), extend(n), retract(n);
  for (std::size_t k = 0; k < n; ++k) {
    y_mm[k] = position_m[k] * 1e3;
    force[k] = options.piston_area_m2 * (pressure_a_pa[k] - options.area_ratio * pressure_b_pa[k]);
    extend[k] = std::max(opening[k], 0.0);
    retract[k] = std::min(opening[k], 0.0);
  }
  const SmoothInputSampling smooth = sample_smooth(a, b, period_s);
  const std::vector<State> y = filter_smooth(y_mm, smooth, period_s);
  const std::vector<State> f = filter_smooth(force, smooth, period_s);
  const std::vector<State> one = filter_held(std::vector<double>(n, 1.0), sample_held(a, b, period_s, 0.0));
  const std::size_t per_segment = (n - skip) / segments;

  // Ap·P_L' + k_h·y' = k_h·k⁺·x⁺ + k_h·k⁻·x⁻ + k_h·v₀ is not linear in k_h alone; written as
  //   Ap·P_L' = θ₀·x⁺ + θ₁·x⁻ + θ₂·1 − θ₃·y'   (θ₃ = k_h in N/mm, y' in mm/s)
  // it is, and k± = θ₀,₁/θ₃, v₀ = θ₂/θ₃.
  const auto accumulate = [&](double delay_s) {
    const HeldInputSampling held = sample_held(a, b, period_s, delay_s);
    const std::vector<State> up = filter_held(extend, held);
    const std::vector<State> down = filter_held(retract, held);
    std::vector<Normal> parts(segments);
    for (std::size_t k = skip; k < skip + per_segment * segments; ++k) {
      const Row row(up[k](0), down[k](0), one[k](0), -y[k](1));
      parts[(k - skip) / per_segment].add(row, f[k](1));
    }
    return parts;
  };

  double best_delay = 0.0;
  double best_rss = std::numeric_limits<double>::infinity();
  for (double delay = 0.0; delay <= options.max_delay_s + 1e-12; delay += options.delay_step_s) {
    Normal total;
    for (const Normal& p : accumulate(delay)) total += p;
    const double rss = total.rss(total.solve());
    if (rss < best_rss) {
      best_rss = rss;
      best_delay = delay;
    }
  }

  const std::vector<Normal> parts = accumulate(best_delay);
  Normal total;
  std::vector<double> stiffness, up, down;
  for (const Normal& p : parts) {
    total += p;
    const Row t = p.solve();
    stiffness.push_back(t(3) * 1e3);
    up.push_back(t(0) / t(3));
    down.push_back(t(1) / t(3));
  }
  const Row theta = total.solve();
  HydraulicFit fit;
  fit.stiffness_n_per_m = {theta(3) * 1e3, std_dev_of_mean(stiffness)};
  fit.extending_mm_per_s = {theta(0) / theta(3), std_dev_of_mean(up)};
  fit.retracting_mm_per_s = {theta(1) / theta(3), std_dev_of_mean(down)};
  fit.leak_speed_mm_per_s = theta(2) / theta(3);
  fit.delay_s = best_delay;
  return fit;
}

}  // namespace hsa::control::identification
