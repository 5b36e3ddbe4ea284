#include "control/identification/closed_loop_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "control/identification/sampled_lti.hpp"

namespace hsa::control::identification {

std::vector<double> simulate_closed_loop(const PlantEstimate& plant, double kp_per_m, const std::vector<double>& setpoint_m,
                                         double initial_position_m, double period_s) {
  // State (y, y', y'') in mm; y''' = −b1·y'' − b0·y' + b0·w, w the speed the opening asks for.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3, 3);
  a(0, 1) = 1.0;
  a(1, 2) = 1.0;
  a(2, 1) = -plant.b0.value;
  a(2, 2) = -plant.b1.value;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(3);
  b(2) = plant.b0.value;
  const HeldInputSampling s = sample_held(a, b, period_s, plant.delay_s);

  const std::size_t n = setpoint_m.size();
  std::vector<double> y(n);
  std::vector<double> drive(n);  // w per period, mm/s
  Eigen::Vector3d x(initial_position_m * 1e3, 0.0, 0.0);
  // Before the record the rod stood still: the opening's speed balanced the leak.
  const auto at = [&](long k) { return k < 0 ? 0.0 : drive[static_cast<std::size_t>(k)]; };
  for (std::size_t k = 0; k < n; ++k) {
    y[k] = x(0) * 1e-3;
    const double xv = std::clamp(kp_per_m * (setpoint_m[k] - y[k]), -1.0, 1.0);
    drive[k] = (xv > 0.0 ? plant.k01.value : plant.k01_retracting.value) * xv + plant.leak_speed_mm_per_s;
    const long now = static_cast<long>(k) - s.whole_periods;
    x = s.phi * x + s.gamma_late * at(now - 1) + s.gamma_now * at(now);
  }
  return y;
}

double fit_index(const std::vector<double>& measured, const std::vector<double>& simulated) {
  if (measured.size() != simulated.size() || measured.empty())
    throw std::invalid_argument("fit index: the two records differ in length");
  double mean = 0.0;
  for (double v : measured) mean += v / static_cast<double>(measured.size());
  double error = 0.0, spread = 0.0;
  for (std::size_t k = 0; k < measured.size(); ++k) {
    error += (measured[k] - simulated[k]) * (measured[k] - simulated[k]);
    spread += (measured[k] - mean) * (measured[k] - mean);
  }
  if (!(spread > 0.0)) throw std::invalid_argument("fit index: the measured output is constant");
  return 1.0 - std::sqrt(error / spread);
}

}  // namespace hsa::control::identification
