#include "control/identification/valve_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "control/identification/closed_loop_model.hpp"
#include "control/identification/identify_run.hpp"
#include "control/identification/valve_equation_error.hpp"

namespace hsa::control::identification {
namespace {

constexpr double kStepA = 0.01;         // a command change larger than the regulator's error (1.5 mA)
constexpr double kPlateauM = 10e-6;     // a spool within this of its highest reading is at the stop …
constexpr std::size_t kPlateauRun = 50;  // … if it stays there this many samples (5 ms at 10 kHz)
constexpr double kSettleS = 0.02;       // a segment's first 20 ms are not scored (its start state)
constexpr int kCoarseIterations = 6;    // per delay of step 2's grid: near the end of the descent

std::string format(const char* fmt, double a, double b = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, fmt, a, b);
  return text;
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x / static_cast<double>(v.size());
  return s;
}

double rms_about_mean(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m) / static_cast<double>(v.size());
  return std::sqrt(s);
}

void check_record(const ValveRecord& r, const ValveFitOptions& o) {
  const std::size_t n = r.spool_m.size();
  if (r.command_a.size() != n || r.current_a.size() != n) throw RunRefused("the record's columns differ in length");
  if (!(r.period_s > 0.0)) throw RunRefused("the record's sample period is not positive");
  for (const auto* v : {&r.command_a, &r.current_a, &r.spool_m})
    for (std::size_t k = 0; k < n; ++k)
      if (!std::isfinite((*v)[k]))
        throw RunRefused(format("sample %.0f is not finite (a disconnected sensor?): record a run without faults",
                                static_cast<double>(k)));
  const double duration = static_cast<double>(n) * r.period_s;
  if (duration < o.min_duration_s)
    throw RunRefused(format("the record lasts %.3f s; record at least %.1f s of excitation", duration,
                            o.min_duration_s));
  if (rms_about_mean(r.current_a) < o.min_current_std_a)
    throw RunRefused(format("the current varies by %.1f mA rms, under the %.0f mA needed to cross the dead band: "
                            "excite with a current that moves (hsa-analyze experiment valve-excite)",
                            rms_about_mean(r.current_a) * 1e3, o.min_current_std_a * 1e3));
  int steps = 0;
  for (std::size_t k = 1; k < n; ++k) steps += std::abs(r.command_a[k] - r.command_a[k - 1]) > kStepA;
  if (steps < o.min_current_steps)
    throw RunRefused(format("the command changes %.0f times; the fit needs at least %.0f transients", steps,
                            o.min_current_steps));
  if (rms_about_mean(r.spool_m) < o.min_spool_std_m)
    throw RunRefused(format("the spool moved by %.1f µm rms, under the %.0f µm the fit needs: raise the "
                            "excitation's amplitude or move its bias off the rest stop",
                            rms_about_mean(r.spool_m) * 1e6, o.min_spool_std_m * 1e6));
}

// Eq 1: I(k) = clamp(I_ref(k − s), 0, I_max) + e with s whole rows; the row convention puts the
// delay at (s + 1)·T (the command is held over the period before its row's time).
RegulatorFit fit_regulator(const ValveRecord& r) {
  const std::size_t n = r.current_a.size();
  RegulatorFit f;
  int best_shift = 0;
  std::size_t best_count = 0;
  for (int s = 0; s <= 20; ++s) {
    std::size_t count = 0;
    for (std::size_t k = static_cast<std::size_t>(s); k < n; ++k)
      count += std::abs(r.current_a[k] - r.command_a[k - static_cast<std::size_t>(s)]) <= kStepA;
    if (count > best_count) {
      best_count = count;
      best_shift = s;
    }
  }
  f.delay_s = (best_shift + 1) * r.period_s;
  const auto shift = static_cast<std::size_t>(best_shift);
  // The limit: where the current stays clearly below the command.
  std::vector<double> limited;
  for (std::size_t k = shift; k < n; ++k) {
    const double command = r.command_a[k - shift];
    f.largest_command_a = std::max(f.largest_command_a, command);
    if (r.current_a[k] < command - kStepA) limited.push_back(r.current_a[k]);
  }
  // The error is drawn anew every period, so the samples at the limit are independent.
  if (limited.size() >= 10) {
    f.limit_reached = true;
    f.current_max_a = {mean(limited), rms_about_mean(limited) / std::sqrt(static_cast<double>(limited.size()))};
  }
  // The error where the command is clear of both clamps (0 and I_max).
  const double upper = f.limit_reached ? f.current_max_a.value - kStepA : std::numeric_limits<double>::infinity();
  double sum = 0.0;
  std::size_t tracked = 0;
  for (std::size_t k = shift; k < n; ++k) {
    const double command = r.command_a[k - shift];
    if (!(command > kStepA && command < upper)) continue;
    const double error = r.current_a[k] - command;
    sum += error * error;
    f.error_max_a = std::max(f.error_max_a, std::abs(error));
    ++tracked;
  }
  f.error_rms_a = tracked > 0 ? std::sqrt(sum / static_cast<double>(tracked)) : 0.0;
  return f;
}

constexpr int kParameters = 7;
using Theta = Eigen::Matrix<double, kParameters, 1>;

Theta to_theta(const ValveModel& m) {
  Theta t;
  t << m.width_a, m.magnetic_lag_s, m.natural_frequency_hz, m.damping_ratio, m.gain_m_per_a, m.rest_position_m,
      m.friction_band_m;
  return t;
}

ValveModel from_theta(const Theta& t, ValveModel m) {
  m.width_a = std::max(t(0), 0.0);
  m.magnetic_lag_s = std::max(t(1), 1e-5);
  m.natural_frequency_hz = std::max(t(2), 1.0);
  m.damping_ratio = std::max(t(3), 1e-3);
  m.gain_m_per_a = std::max(t(4), 1e-9);
  m.rest_position_m = t(5);
  m.friction_band_m = std::max(t(6), 0.0);
  return m;
}

// Finite-difference steps: relative, with floors for the parameters that start at or near 0.
Theta difference_steps(const Theta& t) {
  Theta h;
  h << std::max(1e-3 * t(0), 1e-4), 1e-3 * t(1), 1e-4 * t(2), 1e-3 * t(3), 1e-4 * t(4), 1e-7,
      std::max(1e-3 * t(6), 2e-7);
  return h;
}

// The simulation error over samples [first, last) of the record, scored from `scored`.
struct Problem {
  const std::vector<double>& current;
  const std::vector<double>& spool;
  double period_s;
  std::size_t first, last, scored;
  bool at_rest;            // start at rest on the first reading (the whole record) …
  ValveModelState start;   // … or from this state (a segment)

  [[nodiscard]] std::vector<double> simulate(const ValveModel& m) const {
    return simulate_valve(m, current, period_s, at_rest ? rest_state(m, spool[first]) : start, first, last);
  }
  [[nodiscard]] double cost(const std::vector<double>& y) const {
    double sum = 0.0;
    for (std::size_t k = scored; k < last; ++k) sum += (spool[k] - y[k - first]) * (spool[k] - y[k - first]);
    return sum;
  }
};

struct Refined {
  ValveModel model;
  double cost = std::numeric_limits<double>::infinity();
};

// Levenberg–Marquardt (Marquardt's scaling: the damping is a multiple of the diagonal).
Refined refine(const Problem& p, ValveModel m, int max_iterations = 50) {
  std::vector<double> y = p.simulate(m);
  double cost = p.cost(y);
  Theta theta = to_theta(m);
  double mu = 1e-3;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Theta h = difference_steps(theta);
    std::array<std::vector<double>, kParameters> moved;
    for (int i = 0; i < kParameters; ++i) {
      Theta t = theta;
      t(i) += h(i);
      moved[static_cast<std::size_t>(i)] = p.simulate(from_theta(t, m));
    }
    Eigen::Matrix<double, kParameters, kParameters> jtj = decltype(jtj)::Zero();
    Theta jtr = Theta::Zero();
    for (std::size_t k = p.scored; k < p.last; ++k) {
      const std::size_t j = k - p.first;
      Theta row;
      for (int i = 0; i < kParameters; ++i) row(i) = (moved[static_cast<std::size_t>(i)][j] - y[j]) / h(i);
      jtj.noalias() += row * row.transpose();
      jtr += row * (p.spool[k] - y[j]);
    }
    bool improved = false;
    double gain = 0.0;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, kParameters, kParameters> a = jtj;
      for (int i = 0; i < kParameters; ++i) a(i, i) += mu * std::max(jtj(i, i), 1e-30);
      const ValveModel candidate = from_theta(theta + a.ldlt().solve(jtr), m);
      std::vector<double> yc = p.simulate(candidate);
      const double c = p.cost(yc);
      if (c < cost) {
        gain = (cost - c) / cost;
        m = candidate;
        theta = to_theta(m);
        y = std::move(yc);
        cost = c;
        mu = std::max(mu / 3.0, 1e-9);
        improved = true;
      } else {
        mu *= 4.0;
      }
    }
    if (!improved || gain < 1e-8) break;
  }
  return {m, cost};
}

// The end stop X_max: the highest reading, if the spool stayed within kPlateauM of it for
// kPlateauRun samples or more; the mean of the readings there.
bool find_end_stop(const std::vector<double>& spool, Estimate& stop) {
  const double top = *std::max_element(spool.begin(), spool.end());
  std::vector<double> at;
  std::size_t run = 0;
  for (std::size_t k = 0; k <= spool.size(); ++k) {
    if (k < spool.size() && spool[k] >= top - kPlateauM) {
      ++run;
      continue;
    }
    if (run >= kPlateauRun) at.insert(at.end(), spool.begin() + static_cast<long>(k - run), spool.begin() + static_cast<long>(k));
    run = 0;
  }
  if (at.empty()) return false;
  stop = {mean(at), rms_about_mean(at) / std::sqrt(static_cast<double>(at.size()))};
  return true;
}

}  // namespace

ValveFit fit_valve(const ValveRecord& record, const ValveFitOptions& options) {
  check_record(record, options);
  const std::vector<double>& current = record.current_a;
  const std::vector<double>& spool = record.spool_m;
  const std::size_t n = spool.size();
  const double period = record.period_s;
  ValveFit fit;
  fit.regulator = fit_regulator(record);
  fit.end_stop_reached = find_end_stop(spool, fit.stroke_max_m);

  // Step 1 without the samples near the stops, where the spring equation does not hold: the
  // filters' memory after each.
  const double bottom = *std::min_element(spool.begin(), spool.end());
  const double top = *std::max_element(spool.begin(), spool.end());
  const auto memory = static_cast<std::size_t>(
      std::ceil((10.0 / options.filter_rad_s + 10.0 / (2.0 * std::numbers::pi * options.sensor_bandwidth_hz)) / period));
  std::vector<bool> use(n, true);
  for (std::size_t k = 0, last_near = std::numeric_limits<std::size_t>::max(); k < n; ++k) {
    if (spool[k] <= bottom + 2.0 * kPlateauM || (fit.end_stop_reached && spool[k] >= top - 2.0 * kPlateauM))
      last_near = k;
    use[k] = last_near == std::numeric_limits<std::size_t>::max() || k > last_near + memory;
  }
  EquationErrorOptions eq{.sensor_bandwidth_hz = options.sensor_bandwidth_hz,
                          .max_width_a = options.max_width_a,
                          .width_step_a = options.width_step_a,
                          .max_delay_samples = options.max_delay_samples,
                          .filter_rad_s = options.filter_rad_s};
  try {
    fit.equation_error = fit_valve_equation_error(current, spool, use, period, eq);
  } catch (const std::invalid_argument& e) {
    throw RunRefused(std::string("the record does not show the valve's dynamics: ") + e.what());
  }
  ValveModel start = fit.equation_error;
  start.stroke_max_m = fit.end_stop_reached ? fit.stroke_max_m.value : std::numeric_limits<double>::infinity();

  // Step 2 on a grid of delays: every half sample from 0 to d + 1 with a few iterations each
  // (equation error reads the delay long: it has no friction and weights the LVDT's noise), then
  // to convergence at the best and a quarter sample either side of it.
  const Problem whole{current, spool, period, 0, n, 0, true, {}};
  const auto at_delay = [&](double delay_s, int iterations) {
    ValveModel m = start;
    m.delay_s = delay_s;
    return refine(whole, m, iterations);
  };
  Refined coarse;
  for (int half = 0; half <= 2 * (static_cast<int>(std::lround(start.delay_s / period)) + 1); ++half) {
    Refined r = at_delay(half * 0.5 * period, kCoarseIterations);
    if (r.cost < coarse.cost) coarse = r;
  }
  Refined best;
  for (double quarter : {-0.25, 0.0, 0.25}) {
    const double delay = coarse.model.delay_s + quarter * period;
    if (delay < 0.0) continue;
    Refined r = refine(whole, [&] {
      ValveModel m = coarse.model;
      m.delay_s = delay;
      return m;
    }());
    if (r.cost < best.cost) best = r;
  }
  fit.model = best.model;
  fit.delay_s = best.model.delay_s;
  std::vector<ValveModelState> states;
  fit.model_spool_m = simulate_valve(fit.model, current, period, rest_state(fit.model, spool.front()), 0, n, &states);

  // Step 3: the spread over the segments.
  const auto segments = static_cast<std::size_t>(std::max(options.segments, 1));
  const auto settle = static_cast<std::size_t>(std::ceil(kSettleS / period));
  std::array<std::vector<double>, kParameters + 4> parts;
  const double m_kg = options.assumed_mass_kg;
  const auto derived = [&](const ValveModel& v) {
    const double omega = 2.0 * std::numbers::pi * v.natural_frequency_hz;
    const double k = m_kg * omega * omega;
    return std::array<double, 4>{k, 2.0 * v.damping_ratio * m_kg * omega, v.gain_m_per_a * k, v.friction_band_m * k};
  };
  for (std::size_t j = 0; j < segments && segments > 1; ++j) {
    const std::size_t first = j * n / segments;
    const std::size_t last = (j + 1) * n / segments;
    const Problem part{current, spool, period, first, last, std::min(first + settle, last), false, states[first]};
    const ValveModel v = refine(part, fit.model).model;
    const Theta t = to_theta(v);
    for (int i = 0; i < kParameters; ++i) parts[static_cast<std::size_t>(i)].push_back(t(i));
    const auto d = derived(v);
    for (std::size_t i = 0; i < 4; ++i) parts[kParameters + i].push_back(d[i]);
  }
  const Theta t = to_theta(fit.model);
  const auto d = derived(fit.model);
  Estimate* fields[] = {&fit.width_a,      &fit.magnetic_lag_s,  &fit.natural_frequency_hz, &fit.damping_ratio,
                        &fit.gain_m_per_a, &fit.rest_position_m, &fit.friction_band_m,      &fit.stiffness_n_per_m,
                        &fit.damping_n_s_per_m, &fit.force_constant_n_per_a, &fit.friction_n};
  for (std::size_t i = 0; i < parts.size(); ++i)
    *fields[i] = {i < kParameters ? t(static_cast<int>(i)) : d[i - kParameters], std_dev_of_mean(parts[i])};

  fit.fit_index = fit_index(spool, fit.model_spool_m);
  std::vector<double> residuals(n);
  for (std::size_t k = 0; k < n; ++k) residuals[k] = spool[k] - fit.model_spool_m[k];
  // Lags of 1 ms: 20 of them cover one period of the 50 Hz mode.
  fit.residuals = residual_test(residuals, 20, std::max(1, static_cast<int>(std::lround(1e-3 / period))));
  return fit;
}

IdentifiedValve identified_valve(const ValveFit& fit, double current_max_a) {
  const double limit = fit.regulator.limit_reached ? fit.regulator.current_max_a.value : current_max_a;
  if (!(limit > 0.0))
    throw RunRefused("identified_valve: the record never reached the current limit; give the drive's I_max");
  return {.gain_m_per_a = fit.gain_m_per_a.value,
          .rest_position_m = fit.rest_position_m.value,
          .natural_frequency_hz = fit.natural_frequency_hz.value,
          .damping_ratio = fit.damping_ratio.value,
          .magnetic_lag_s = fit.magnetic_lag_s.value,
          .width_a = fit.width_a.value,
          .delay_s = fit.regulator.delay_s + fit.delay_s,
          .current_max_a = limit};
}

}  // namespace hsa::control::identification
