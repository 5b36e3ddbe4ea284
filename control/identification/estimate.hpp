// An identified number and its standard deviation. The identification code gets the deviation
// from the spread of the estimates over independent parts of the record (batch means): the
// equation errors it minimizes are filtered and so correlated from sample to sample, and the
// textbook σ²·(AᵀA)⁻¹ would understate the uncertainty by the correlation length.
#pragma once

#include <cmath>
#include <vector>

namespace hsa::control::identification {

struct Estimate {
  double value = 0.0;
  double std_dev = 0.0;
};

// The standard deviation of the mean of `parts` (sample deviation over √n); 0 for fewer than 2.
[[nodiscard]] inline double std_dev_of_mean(const std::vector<double>& parts) {
  const auto n = static_cast<double>(parts.size());
  if (parts.size() < 2) return 0.0;
  double mean = 0.0;
  for (double p : parts) mean += p / n;
  double sum = 0.0;
  for (double p : parts) sum += (p - mean) * (p - mean);
  return std::sqrt(sum / (n - 1.0) / n);
}

}  // namespace hsa::control::identification
