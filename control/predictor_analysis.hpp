#pragma once

#include <array>
#include <complex>

#include "control/state_predictor.hpp"

namespace hsa::control {

// Frequency analysis of the state predictor (Canuto et al. 2014, eqs 18–23).
//
// The position transfer V_px(z) = x(z)/y_x(z) is evaluated from the state space,
// V_px(z) = [1 0 0 0]·(z·I − A)⁻¹·L, which does not rely on eq 23; eq 23's closed form in
// s = z − 1, (c2·s² + c1·s + c0)/(s⁴ + c3·s³ + c2·s² + c1·s + c0), is provided separately so the
// two can be checked against each other (Theorem 1).
//
// The peak of |V_px(e^{j2πfT})| over (0, f_N) (f_N = 1/(2T)) is bracketed on a uniform grid and
// refined by golden-section search; the −3 dB frequency is the first frequency above the peak
// where |V_px| falls to 1/√2, bracketed on the same grid and refined by bisection.
struct PredictorAnalysis {
  PredictorCoefficients coefficients{};
  PredictorGains gains{};
  std::array<std::complex<double>, 4> eigenvalues{};  // of A, in decreasing real part
  double peak_magnitude = 0.0;
  double peak_hz = 0.0;
  double minus_3db_hz = 0.0;  // NaN when |V_px| stays above 1/√2 up to f_N
};

std::complex<double> position_response(const PredictorGains& gains, double frequency_hz, double period_s);
std::complex<double> position_response_eq23(const PredictorCoefficients& c, double frequency_hz,
                                            double period_s);

// Throws std::invalid_argument for γ outside (0, 1], l_d outside eq 21's set, or period <= 0.
PredictorAnalysis analyze_predictor(const std::array<double, 4>& gamma, double period_s, double l_d = 0.0);

}  // namespace hsa::control
