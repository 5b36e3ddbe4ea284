#include "control/state_predictor.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "control/predictor_analysis.hpp"

namespace hsa::control {
namespace {

constexpr double kT = 1e-4;  // the valve loop's 10 kHz

// Eq 19 of Canuto et al. (2014) with Table 2's γ gives the coefficients and gains as exact
// decimals (they are sums of products of
// 0.4 and 0.04), so only floating-point rounding separates them from ours.
constexpr double kExactDecimal = 1e-12;

TEST(StatePredictor, CoefficientsOfTable2Eigenvalues) {
  const PredictorCoefficients c = predictor_coefficients(kTable2Gamma);
  EXPECT_NEAR(c.c3, 0.88, kExactDecimal);
  EXPECT_NEAR(c.c2, 0.2256, kExactDecimal);
  EXPECT_NEAR(c.c1, 0.01408, kExactDecimal);
  EXPECT_NEAR(c.c0, 0.000256, kExactDecimal);
}

TEST(StatePredictor, GainsOfTable2EigenvaluesWithZeroLd) {
  const PredictorGains g = predictor_gains(kTable2Gamma);
  EXPECT_NEAR(g.beta, 0.88, kExactDecimal);
  EXPECT_NEAR(g.l_a, 0.2256, kExactDecimal);
  EXPECT_EQ(g.l_d, 0.0);
  EXPECT_NEAR(g.m_a, -0.184448, kExactDecimal);
  EXPECT_NEAR(g.m_d, 0.000256, kExactDecimal);
}

// The double eigenvalues of A form Jordan blocks, which a perturbation of the size of rounding
// (1e-16) splits by its square root (about 1e-8); 1e-6 is well clear of that and far tighter
// than any design tolerance.
constexpr double kDefectiveEigenvalue = 1e-6;

TEST(StatePredictor, EigenvaluesOfAAreOneMinusGamma) {
  for (const double l_d : {0.0, -0.1, 0.0002}) {  // -0.18 ≤ l_d ≤ 0.00029 by eq 21
    const Eigen::Matrix4d a = predictor_state_matrix(predictor_gains(kTable2Gamma, l_d));
    Eigen::Vector4cd ev = Eigen::EigenSolver<Eigen::Matrix4d>(a, false).eigenvalues();
    std::sort(ev.data(), ev.data() + 4, [](auto x, auto y) { return x.real() < y.real(); });
    const double expected[] = {0.6, 0.6, 0.96, 0.96};
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(ev(k).real(), expected[k], kDefectiveEigenvalue) << "l_d = " << l_d;
      EXPECT_NEAR(ev(k).imag(), 0.0, kDefectiveEigenvalue) << "l_d = " << l_d;
    }
  }
}

TEST(StatePredictor, AnyGammaGivesItsOwnEigenvalues) {
  const std::array<double, 4> gamma{1.0, 0.5, 0.2, 0.05};  // distinct: well conditioned
  Eigen::Vector4cd ev =
      Eigen::EigenSolver<Eigen::Matrix4d>(predictor_state_matrix(predictor_gains(gamma)), false).eigenvalues();
  std::sort(ev.data(), ev.data() + 4, [](auto x, auto y) { return x.real() < y.real(); });
  const double expected[] = {0.0, 0.5, 0.8, 0.95};
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(ev(k).real(), expected[k], 1e-12);
}

TEST(StatePredictor, RejectsGammaOutsideTheUnitIntervalAndLdOutsideEq21) {
  EXPECT_THROW(predictor_coefficients({0.4, 0.4, 0.0, 0.04}), std::invalid_argument);
  EXPECT_THROW(predictor_coefficients({0.4, 1.5, 0.04, 0.04}), std::invalid_argument);
  EXPECT_THROW(predictor_coefficients({0.4, -0.4, 0.04, 0.04}), std::invalid_argument);
  EXPECT_NO_THROW(predictor_coefficients({1.0, 1.0, 1.0, 1.0}));
  // C = [c1 − c3·c2, c0/c3] = [−0.184448, 0.000290909…]
  EXPECT_THROW(predictor_gains(kTable2Gamma, -0.19), std::invalid_argument);
  EXPECT_THROW(predictor_gains(kTable2Gamma, 0.0003), std::invalid_argument);
  EXPECT_THROW(StatePredictor(predictor_gains(kTable2Gamma), 0.0), std::invalid_argument);
}

// A skipped span is caught up with the measurement held: the same bits as running every sample
// on that measurement, since the same steps run in the same order.
TEST(StatePredictor, ElapsedSamplesAdvanceTheStateAsConsecutiveUpdatesWould) {
  StatePredictor every(predictor_gains(kTable2Gamma), kT), skipping(predictor_gains(kTable2Gamma), kT);
  every.reset(0.0);
  skipping.reset(0.0);
  for (int i = 0; i < 7; ++i) every.update(1e-4);
  const PredictorOutput a = every.update(1e-4);
  const PredictorOutput b = skipping.update(1e-4, 8);
  EXPECT_EQ(a.position_m, b.position_m);
  EXPECT_EQ(a.velocity_m_s, b.velocity_m_s);
  EXPECT_EQ(a.acceleration_m_s2, b.acceleration_m_s2);
  EXPECT_EQ(every.state(), skipping.state());
  // The catch-up is bounded: a gap longer than kMaxCatchUp costs no more than kMaxCatchUp steps.
  StatePredictor capped(predictor_gains(kTable2Gamma), kT), bound(predictor_gains(kTable2Gamma), kT);
  capped.reset(0.0);
  bound.reset(0.0);
  capped.update(1e-4, 1'000'000);
  bound.update(1e-4, StatePredictor::kMaxCatchUp + 1);
  EXPECT_EQ(capped.state(), bound.state());
}

// step() writes eq 15 out with A's zeros and ones; it must stay the matrix form A·x + L·y_x and
// the output rows C_m, D_m, for any l_d of eq 21 (l_d = 0 would hide a wrong l_d or m_d term).
TEST(StatePredictor, TheWrittenOutUpdateIsEq15sMatrixForm) {
  for (const double l_d : {0.0, -0.1, 0.0002}) {
    const PredictorGains g = predictor_gains(kTable2Gamma, l_d);
    const Eigen::Matrix4d a = predictor_state_matrix(g);
    const Eigen::Vector4d l = predictor_input_vector(g);
    StatePredictor predictor(g, kT);
    predictor.reset(2e-4);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector4d x = predictor.state();
      const double y = 1e-3 * std::sin(0.05 * i) + 1e-6 * std::cos(1.7 * i);
      const PredictorOutput out = predictor.update(y);
      const double acceleration = -g.l_a * x(0) + x(2) + g.m_a * x(3) + g.l_a * y;  // C_m, D_m row 3
      EXPECT_EQ(out.position_m, x(0));
      EXPECT_NEAR(out.velocity_m_s, x(1) / kT, 1e-12 * (1.0 + std::abs(x(1) / kT)));
      EXPECT_NEAR(out.acceleration_m_s2, acceleration / (kT * kT), 1e-9 * (1.0 + std::abs(acceleration / (kT * kT))));
      const Eigen::Vector4d next = a * x + l * y;
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(predictor.state()(k), next(k), 1e-12 * (1e-3 + std::abs(next(k)))) << "l_d = " << l_d << ", sample " << i << ", state " << k;
    }
  }
}

TEST(StatePredictor, StartsAtRestWithoutTransient) {
  StatePredictor p(predictor_gains(kTable2Gamma), kT);
  p.reset(-1.7e-3);
  for (int k = 0; k < 100; ++k) {
    const PredictorOutput y = p.update(-1.7e-3);
    EXPECT_DOUBLE_EQ(y.position_m, -1.7e-3);
    EXPECT_EQ(y.velocity_m_s, 0.0);
    EXPECT_EQ(y.acceleration_m_s2, 0.0);
  }
}

// The model error 1 − V_px is (s⁴ + c3·s³)/P_A(s) in s = z − 1 (eq 23): a triple zero at z = 1, so
// position, velocity and acceleration of a parabola are tracked without steady error.
TEST(StatePredictor, TracksAParabolaExactlyInSteadyState) {
  StatePredictor p(predictor_gains(kTable2Gamma), kT);
  p.reset(0.0);
  const double x0 = -1e-3, v0 = 0.02, a0 = 30.0;  // m, m/s, m/s²
  PredictorOutput y{};
  int k = 0;
  for (; k <= 3000; ++k) {  // the slowest mode decays as 0.96^k·k: 1e-50 after 3000 samples
    const double t = k * kT;
    y = p.update(x0 + v0 * t + 0.5 * a0 * t * t);
  }
  const double t = (k - 1) * kT;
  // Positions reach 1.4 m, whose rounding (2e-16 m) becomes 2e-8 m/s² once divided by T².
  EXPECT_NEAR(y.position_m, x0 + v0 * t + 0.5 * a0 * t * t, 1e-12);
  // v is the forward increment x(i+1) − x(i) of the prediction, a the second forward difference.
  EXPECT_NEAR(y.velocity_m_s, v0 + a0 * (t + 0.5 * kT), 1e-9);
  EXPECT_NEAR(y.acceleration_m_s2, a0, 1e-6);
}

// A sine through update() comes out with the amplitude and phase of the analysis' V_px, so the
// time-domain class and the frequency analysis describe the same system.
TEST(StatePredictor, SteadyStateSineMatchesTheFrequencyResponse) {
  const PredictorGains g = predictor_gains(kTable2Gamma);
  for (const double f : {50.0, 186.0, 834.0}) {
    StatePredictor p(g, kT);
    p.reset(0.0);
    const double w = 2.0 * std::numbers::pi * f * kT;
    // Settle for 10000 samples (0.96^10000 ≈ 1e-177), then correlate over the next 10000.
    std::complex<double> correlation = 0.0;
    int n = 0;
    for (int k = 0; k < 20000; ++k) {
      const double x = p.update(std::sin(w * k)).position_m;
      if (k >= 10000) {
        correlation += x * std::polar(1.0, -w * k);
        ++n;
      }
    }
    // n·T = 1 s holds a whole number of periods of each (integer) frequency, so the image at
    // −f cancels exactly in the correlation and only rounding remains.
    const std::complex<double> measured = 2.0 * correlation / static_cast<double>(n) * std::complex<double>(0.0, 1.0);
    const std::complex<double> expected = position_response(g, f, kT);
    EXPECT_NEAR(std::abs(measured - expected), 0.0, 1e-9) << f << " Hz";
  }
}

}  // namespace
}  // namespace hsa::control
