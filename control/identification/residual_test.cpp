#include "control/identification/residual_test.hpp"

#include <cmath>
#include <stdexcept>

namespace hsa::control::identification {

ResidualTest residual_test(const std::vector<double>& residuals, int max_lag, int stride) {
  std::vector<double> e;
  for (std::size_t k = 0; k < residuals.size(); k += static_cast<std::size_t>(std::max(stride, 1)))
    e.push_back(residuals[k]);
  const std::size_t n = e.size();
  if (max_lag < 1 || n < 2 * static_cast<std::size_t>(max_lag))
    throw std::invalid_argument("residual test: too few samples for the lags");
  double mean = 0.0;
  for (double v : e) mean += v / static_cast<double>(n);
  for (double& v : e) v -= mean;
  double energy = 0.0;
  for (double v : e) energy += v * v;
  ResidualTest t;
  t.band = 2.576 / std::sqrt(static_cast<double>(n));
  for (int lag = 1; lag <= max_lag; ++lag) {
    double sum = 0.0;
    for (std::size_t k = 0; k + static_cast<std::size_t>(lag) < n; ++k) sum += e[k] * e[k + static_cast<std::size_t>(lag)];
    const double r = energy > 0.0 ? sum / energy : 0.0;
    t.autocorrelation.push_back(r);
    if (std::abs(r) > t.band) ++t.outside;
  }
  return t;
}

}  // namespace hsa::control::identification
