#include "control/predictor_analysis.hpp"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace hsa::control {
namespace {

constexpr double kT = 1e-4;

// Recomputed independently from Canuto et al. (2014), eqs 18–23 with Table 2's γ: peak ≈ 1.28
// near 186 Hz, −3 dB ≈ 834 Hz, each to half a unit of the last written
// digit (0.005, 0.5 Hz).
TEST(PredictorAnalysis, PositionTransferOfTable2Design) {
  const PredictorAnalysis a = analyze_predictor(kTable2Gamma, kT);
  EXPECT_NEAR(a.peak_magnitude, 1.28, 0.005);
  EXPECT_NEAR(a.peak_hz, 186.0, 0.5);
  EXPECT_NEAR(a.minus_3db_hz, 834.0, 0.5);
}

TEST(PredictorAnalysis, ReportsCoefficientsGainsAndEigenvalues) {
  const PredictorAnalysis a = analyze_predictor(kTable2Gamma, kT);
  EXPECT_NEAR(a.coefficients.c2, 0.2256, 1e-12);
  EXPECT_NEAR(a.gains.m_a, -0.184448, 1e-12);
  // Double eigenvalues: see test_state_predictor.cpp for the 1e-6.
  const double expected[] = {0.96, 0.96, 0.6, 0.6};
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(a.eigenvalues[k].real(), expected[k], 1e-6);
}

TEST(PredictorAnalysis, PeakIsAMaximumAndMinus3dBIsHalfPower) {
  const PredictorAnalysis a = analyze_predictor(kTable2Gamma, kT);
  const PredictorGains g = a.gains;
  for (const double df : {-1.0, -0.1, 0.1, 1.0}) {
    EXPECT_LT(std::abs(position_response(g, a.peak_hz + df, kT)), a.peak_magnitude);
  }
  EXPECT_NEAR(std::abs(position_response(g, a.minus_3db_hz, kT)), 1.0 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(std::abs(position_response(g, 0.0, kT)), 1.0, 1e-12);  // V_px(1) = c0/c0
}

// Theorem 1: the state-space response equals eq 23's closed form for every l_d in eq 21's set.
TEST(PredictorAnalysis, StateSpaceMatchesEq23ForAnyLd) {
  const PredictorCoefficients c = predictor_coefficients(kTable2Gamma);
  const double l_d_min = c.c1 - c.c3 * c.c2;
  const double l_d_max = c.c0 / c.c3;
  for (const double l_d : {0.0, l_d_min, 0.5 * l_d_min, l_d_max}) {
    const PredictorGains g = predictor_gains(kTable2Gamma, l_d);
    for (const double f : {1.0, 50.0, 186.0, 834.0, 2500.0, 4999.0}) {
      const auto ss = position_response(g, f, kT);
      const auto closed_form = position_response_eq23(c, f, kT);
      EXPECT_NEAR(std::abs(ss - closed_form), 0.0, 1e-9 * std::abs(closed_form)) << "l_d " << l_d << ", " << f << " Hz";
    }
  }
}

TEST(PredictorAnalysis, RejectsBadInput) {
  EXPECT_THROW(analyze_predictor(kTable2Gamma, 0.0), std::invalid_argument);
  EXPECT_THROW(analyze_predictor({0.4, 0.4, 0.04, 1.2}, kT), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
