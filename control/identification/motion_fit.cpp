#include "control/identification/motion_fit.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "control/identification/zero_phase_filter.hpp"

namespace hsa::control::identification {

MotionFit fit_motion(const std::vector<double>& setpoint_m, const std::vector<double>& position_m,
                     const std::vector<double>& pressure_a_pa, const std::vector<double>& pressure_b_pa,
                     double period_s, const MotionFitOptions& options) {
  const std::size_t n = position_m.size();
  if (setpoint_m.size() != n || pressure_a_pa.size() != n || pressure_b_pa.size() != n)
    throw std::invalid_argument("motion fit: the records differ in length");
  if (!(options.piston_area_m2 > 0.0) || !(options.area_ratio > 0.0) || !(period_s > 0.0))
    throw std::invalid_argument("motion fit: piston area, area ratio and period must be positive");
  const double rate = 1.0 / period_s;

  std::vector<double> velocity(n, 0.0), acceleration(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    velocity[k] = (position_m[k + 1] - position_m[k - 1]) / (2.0 * period_s);
    acceleration[k] = (position_m[k + 1] - 2.0 * position_m[k] + position_m[k - 1]) / (period_s * period_s);
  }
  velocity = butterworth4_zero_phase(velocity, options.derivative_cutoff_hz, rate);
  acceleration = butterworth4_zero_phase(acceleration, options.derivative_cutoff_hz, rate);
  const std::vector<double> pa = butterworth4_zero_phase(pressure_a_pa, options.pressure_cutoff_hz, rate);
  const std::vector<double> pb = butterworth4_zero_phase(pressure_b_pa, options.pressure_cutoff_hz, rate);

  const auto window = static_cast<std::size_t>(std::lround(options.window_s / period_s));
  struct Window {
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
  };
  std::vector<Window> windows;
  for (std::size_t start = 1; start + window + 1 < n; ++start) {
    if (setpoint_m[start] == setpoint_m[start - 1]) continue;
    Window w;
    for (std::size_t k = start; k < start + window; ++k) {
      if (std::abs(velocity[k]) < options.min_speed_m_s) continue;
      const Eigen::Vector4d row(acceleration[k], velocity[k], 1.0, velocity[k] > 0.0 ? 1.0 : -1.0);
      const double force = options.piston_area_m2 * (pa[k] - options.area_ratio * pb[k]);
      w.ata.noalias() += row * row.transpose();
      w.atb += row * force;
    }
    windows.push_back(w);
  }
  constexpr std::size_t kGroups = 5;
  if (windows.size() < 2 * kGroups)
    throw std::invalid_argument("motion fit: fewer than 10 setpoint changes with a full window");
  // One window rarely moves both ways, so F_e and F_c part only over several: the spread is taken
  // over kGroups runs of consecutive windows.
  Window total;
  std::vector<double> masses, dampings, forces, frictions;
  for (std::size_t g = 0; g < kGroups; ++g) {
    Window part;
    for (std::size_t i = g * windows.size() / kGroups; i < (g + 1) * windows.size() / kGroups; ++i) {
      part.ata += windows[i].ata;
      part.atb += windows[i].atb;
    }
    total.ata += part.ata;
    total.atb += part.atb;
    const Eigen::Vector4d theta = part.ata.ldlt().solve(part.atb);
    masses.push_back(theta(0));
    dampings.push_back(theta(1));
    forces.push_back(theta(2));
    frictions.push_back(theta(3));
  }
  const Eigen::Vector4d theta = total.ata.ldlt().solve(total.atb);
  MotionFit fit;
  fit.mass_kg = {theta(0), std_dev_of_mean(masses)};
  fit.damping_n_s_per_m = {theta(1), std_dev_of_mean(dampings)};
  fit.external_force_n = {theta(2), std_dev_of_mean(forces)};
  fit.dry_friction_n = {theta(3), std_dev_of_mean(frictions)};
  fit.windows = static_cast<int>(windows.size());
  return fit;
}

}  // namespace hsa::control::identification
