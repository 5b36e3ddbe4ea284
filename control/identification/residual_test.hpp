// Residual analysis of an identified model (Ljung 1999, section 16.6): the normalized
// autocorrelation of the residuals ε = y − y_s at lags 1…max_lag,
//
//   r(τ) = Σ ε(k)·ε(k+τ) / Σ ε(k)²,
//
// lies inside ±z/√N (z = 2.576: the 99 % band of a white sequence of N samples) at every lag if
// what the model leaves is white noise. Lags are counted in samples of `stride` periods, so the
// test looks at the time scale of the plant's dynamics rather than of the encoder's quantization.
#pragma once

#include <vector>

namespace hsa::control::identification {

struct ResidualTest {
  std::vector<double> autocorrelation;  // lags 1…max_lag
  double band = 0.0;                    // 2.576/√N
  int outside = 0;                      // lags outside ±band
  [[nodiscard]] bool white() const { return outside == 0; }
};

// Throws std::invalid_argument when there are fewer than 2·max_lag samples after striding.
[[nodiscard]] ResidualTest residual_test(const std::vector<double>& residuals, int max_lag = 20, int stride = 1);

}  // namespace hsa::control::identification
