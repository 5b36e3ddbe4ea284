#include "control/identification/identify_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include "control/identification/closed_loop_model.hpp"

namespace hsa::control::identification {
namespace {

std::string format(const char* fmt, double a, double b = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, fmt, a, b);
  return text;
}

double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

double std_dev(const std::vector<double>& v) {
  const double m = mean(v);
  double sum = 0.0;
  for (double x : v) sum += (x - m) * (x - m);
  return std::sqrt(sum / static_cast<double>(v.size()));
}

void check_run(const ClosedLoopRun& run, const RunLimits& limits) {
  const std::size_t n = run.position_m.size();
  for (const auto* v : {&run.setpoint_m, &run.opening, &run.pressure_a_pa, &run.pressure_b_pa})
    if (v->size() != n) throw RunRefused("the run's columns differ in length");
  for (const auto* v : {&run.setpoint_m, &run.position_m, &run.opening, &run.pressure_a_pa, &run.pressure_b_pa})
    for (double x : *v)
      if (!std::isfinite(x))
        throw RunRefused("the run has a non-finite sample (a disconnected sensor?): record a run without faults");
  const double duration = static_cast<double>(n) * run.period_s;
  if (duration < limits.min_duration_s)
    throw RunRefused(format("the run lasts %.1f s; record at least %.0f s (the paper recorded 50 s per point)",
                            duration, limits.min_duration_s));
  int changes = 0;
  for (std::size_t k = 1; k < n; ++k) changes += run.setpoint_m[k] != run.setpoint_m[k - 1];
  if (changes < limits.min_setpoint_changes)
    throw RunRefused(format("the setpoint changes %.0f times; the fit needs at least %.0f transients: shorten the "
                            "switching time or record longer",
                            changes, limits.min_setpoint_changes));
  if (std_dev(run.position_m) < limits.min_position_std_m)
    throw RunRefused(format("the rod moved by %.1f µm rms, under the %.0f µm the fit needs above the encoder's "
                            "resolution and the seals' friction: raise the excitation amplitude",
                            std_dev(run.position_m) * 1e6, limits.min_position_std_m * 1e6));
  const auto saturated = std::count_if(run.opening.begin(), run.opening.end(),
                                       [&](double x) { return std::abs(x) >= limits.saturation; });
  if (static_cast<double>(saturated) > limits.max_saturated_fraction * static_cast<double>(n))
    throw RunRefused(format("the valve was saturated in %.2f %% of the samples: the model is linear in the opening; "
                            "lower the excitation amplitude or the P gain",
                            100.0 * static_cast<double>(saturated) / static_cast<double>(n)));
}

// xv = K·(r − y) + c by least squares; refuses the run when the opening is not that.
double proportional_gain(const ClosedLoopRun& run, double max_misfit) {
  const auto n = static_cast<Eigen::Index>(run.opening.size());
  Eigen::MatrixXd a(n, 2);
  Eigen::VectorXd b(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    a(k, 0) = run.setpoint_m[i] - run.position_m[i];
    a(k, 1) = 1.0;
    b(k) = run.opening[i];
  }
  const Eigen::Vector2d theta = a.colPivHouseholderQr().solve(b);
  const double misfit = (a * theta - b).norm() / (b.array() - b.mean()).matrix().norm();
  if (!(misfit <= max_misfit) || !(theta(0) > 0.0))
    throw RunRefused(format("the opening is not proportional to the following error (misfit %.1f %%): identify "
                            "needs a run under a P controller, as the paper's (section 3.1.1)",
                            100.0 * misfit));
  return theta(0);
}

}  // namespace

Identification identify_run(const ClosedLoopRun& run, const IdentifyOptions& options) {
  check_run(run, options.limits);
  Identification id;
  id.duration_s = static_cast<double>(run.position_m.size()) * run.period_s;
  id.working_point_m = mean(run.setpoint_m);
  id.kp_per_m = proportional_gain(run, options.limits.max_p_law_misfit);
  for (double x : run.opening) id.peak_opening = std::max(id.peak_opening, std::abs(x));

  MotionFitOptions motion = options.motion;
  motion.piston_area_m2 = options.hydraulics.piston_area_m2;
  motion.area_ratio = options.hydraulics.area_ratio;
  id.motion = fit_motion(run.setpoint_m, run.position_m, run.pressure_a_pa, run.pressure_b_pa, run.period_s, motion);
  id.hydraulics = fit_hydraulics(run.opening, run.position_m, run.pressure_a_pa, run.pressure_b_pa, run.period_s,
                                 options.hydraulics);
  const Estimate& m = id.motion.mass_kg;
  const Estimate& sigma = id.motion.damping_n_s_per_m;
  const Estimate& kh = id.hydraulics.stiffness_n_per_m;
  if (!(m.value > 0.0) || !(sigma.value > 0.0) || !(kh.value > 0.0) || !(id.hydraulics.extending_mm_per_s.value > 0.0))
    throw RunRefused("the fits gave a mass, damping, stiffness or valve gain that is not positive: the run does not "
                     "show the plant's dynamics; raise the P gain to an underdamped response or the amplitude");
  // Ratios of independent estimates: relative deviations add in quadrature.
  const auto ratio = [](const Estimate& num, const Estimate& den) {
    const double r = num.value / den.value;
    return Estimate{r, std::abs(r) * std::hypot(num.std_dev / num.value, den.std_dev / den.value)};
  };
  id.plant.b0 = ratio(kh, m);
  id.plant.b1 = ratio(sigma, m);
  id.plant.k01 = id.hydraulics.extending_mm_per_s;
  id.plant.k01_retracting = id.hydraulics.retracting_mm_per_s;
  id.plant.delay_s = id.hydraulics.delay_s;
  id.plant.leak_speed_mm_per_s = id.hydraulics.leak_speed_mm_per_s;

  id.model_position_m =
      simulate_closed_loop(id.plant, id.kp_per_m, run.setpoint_m, run.position_m.front(), run.period_s);
  id.fit_index = fit_index(run.position_m, id.model_position_m);
  std::vector<double> residuals(run.position_m.size());
  for (std::size_t k = 0; k < residuals.size(); ++k) residuals[k] = run.position_m[k] - id.model_position_m[k];
  // Lags of 5 ms: the plants' fastest mode (√b0 ≈ 100 rad/s) over 20 lags of 5 ms = 0.1 s.
  id.residuals = residual_test(residuals, 20, std::max(1, static_cast<int>(std::lround(5e-3 / run.period_s))));
  return id;
}

}  // namespace hsa::control::identification
