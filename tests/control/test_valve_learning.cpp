// The valve loop's learning law (control/valve_learning_design.hpp offline, control/valve_learning.hpp
// on the RT thread): its Q is zero-phase, the design converges on an identified-like valve, the RT
// filter applies exactly the designed update and learns a repeated error away on a model loop, and
// update() does not allocate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "control/valve_learning.hpp"
#include "control/valve_learning_design.hpp"
#include "control/valve_law.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

// An identified valve as identified_valve() gives it for the paper's valve (round figures).
IdentifiedValve paper_like() {
  return {.gain_m_per_a = 1.0 / 548.3, .rest_position_m = -2.5e-3, .natural_frequency_hz = 50.0,
          .damping_ratio = 0.3, .magnetic_lag_s = 1.5e-3, .width_a = 0.3, .delay_s = 0.45e-3, .current_max_a = 3.0};
}

ValveLawParams loop() { return identified_valve_law(paper_like(), ValveLawStep::model_inverse); }

TEST(ValveLearningDesign, QIsSymmetricWithUnitDcGainAndNeverAboveOne) {
  const ValveLearningDesign d = design_valve_learning(paper_like(), loop(), 1000, valve_learning_settings());
  const std::size_t m = d.filter.size() / 2;
  double sum = 0.0;
  for (std::size_t j = 0; j < d.filter.size(); ++j) {
    EXPECT_NEAR(d.filter[j], d.filter[2 * m - j], 1e-12) << "zero phase: q_j = q_−j";
    sum += d.filter[j];
  }
  EXPECT_NEAR(sum, 1.0, 1e-9) << "Q(0) = 1: the learning keeps what it learned at DC";
  // Its response at every harmonic is real (zero phase) and within [0, 1].
  for (int n = 0; n <= 500; ++n) {
    std::complex<double> q = 0.0;
    for (int j = -static_cast<int>(m); j <= static_cast<int>(m); ++j)
      q += d.filter[static_cast<std::size_t>(j) + m] * std::polar(1.0, -2.0 * std::numbers::pi * j * n / 1000.0);
    EXPECT_NEAR(q.imag(), 0.0, 1e-12);
    EXPECT_GE(q.real(), -1e-6);
    EXPECT_LE(q.real(), 1.0 + 1e-9);
  }
  const double f_q = valve_learning_settings().filter_hz;
  const int n_q = static_cast<int>(std::lround(f_q / 10.0));  // harmonic at f_Q for a 10 Hz period
  std::complex<double> q = 0.0;
  for (int j = -static_cast<int>(m); j <= static_cast<int>(m); ++j)
    q += d.filter[static_cast<std::size_t>(j) + m] * std::polar(1.0, -2.0 * std::numbers::pi * j * n_q / 1000.0);
  EXPECT_NEAR(std::abs(q), 1.0 / std::sqrt(2.0), 0.01) << "−3 dB at f_Q";
}

TEST(ValveLearningDesign, ConvergesOnTheIdentifiedLoopAtEveryHarmonic) {
  for (int n : {1000, 100, 40}) {  // 10, 100 and 250 Hz references
    const ValveLearningDesign d = design_valve_learning(paper_like(), loop(), n, valve_learning_settings());
    const std::vector<double> rho = valve_learning_convergence(paper_like(), loop(), d);
    ASSERT_EQ(rho.size(), static_cast<std::size_t>(n / 2 + 1));
    for (std::size_t k = 0; k < rho.size(); ++k) EXPECT_LT(rho[k], 1.0) << "N " << n << ", harmonic " << k;
    // At DC H inverts G: ρ = 1 − k_L untruncated; the truncation to ±M moves it by the tails left out
    // (most at N = 40, where M = 19).
    EXPECT_NEAR(rho[0], 1.0 - valve_learning_settings().gain, 0.02);
    EXPECT_EQ(d.convergence, *std::max_element(rho.begin(), rho.end()));
  }
  // The loop's delay: the 300 Hz reference filter's 3/ω_r plus the valve's, in whole samples.
  const ValveLearningDesign d = design_valve_learning(paper_like(), loop(), 1000, valve_learning_settings());
  EXPECT_GE(d.delay_samples, 16);
  EXPECT_LE(d.delay_samples, 25);
}

TEST(ValveLearningDesign, RefusesWhatItCannotDesign) {
  const ValveLearningSettings ok = valve_learning_settings();
  EXPECT_THROW(design_valve_learning(paper_like(), loop(), 3, ok), std::invalid_argument);
  ValveLearningSettings bad = ok;
  bad.gain = 2.0;
  EXPECT_THROW(design_valve_learning(paper_like(), loop(), 1000, bad), std::invalid_argument);
  bad = ok;
  bad.filter_hz = 0.0;
  EXPECT_THROW(design_valve_learning(paper_like(), loop(), 1000, bad), std::invalid_argument);
  EXPECT_THROW(identified_valve_law(paper_like(), ValveLawStep::learning, 0.10005), std::invalid_argument);
  EXPECT_THROW(ValveLearning(10, 10, {1.0}, {1.0}), std::invalid_argument);
  EXPECT_THROW(ValveLearning(10, 0, {1.0, 0.0}, {1.0, 0.0}), std::invalid_argument);
}

// The RT filter applies u(i) = Σ q_j u(i − N − j) + Σ h_j e(i − N − j), with e = r(i − D) − x(i).
TEST(ValveLearning, AppliesTheDesignedUpdateOnePeriodLater) {
  // q = δ, h: a two-tap kernel with one sample of lead (j = −1) and one of lag (j = +1).
  ValveLearning learning(8, 2, {0.0, 1.0, 0.0}, {0.5, 0.0, 0.25});
  std::vector<double> e(24, 0.0), u(24, 0.0);
  for (int i = 0; i < 24; ++i) {
    const double r = 1e-3 * i, x = 1e-4 * std::sin(i);
    u[static_cast<std::size_t>(i)] = learning.update(r, x);
    e[static_cast<std::size_t>(i)] = (i >= 2 ? 1e-3 * (i - 2) : r) - x;
  }
  for (int i = 0; i < 24; ++i) {
    double expect = 0.0;
    if (i - 8 >= 0) expect += u[static_cast<std::size_t>(i - 8)];
    if (i - 8 + 1 >= 0 && i - 8 + 1 < i) expect += 0.5 * e[static_cast<std::size_t>(i - 7)];
    if (i - 9 >= 0) expect += 0.25 * e[static_cast<std::size_t>(i - 9)];
    EXPECT_NEAR(u[static_cast<std::size_t>(i)], expect, 1e-15) << "sample " << i;
  }
  learning.reset();
  EXPECT_EQ(learning.update(1.0, 0.0), 0.0) << "reset forgets";
}

// The designed law on a sampled model of its own loop (the valve's second order and lag behind the
// reference filter, as G models it without the feedback): the repeated error of a 50 Hz sine, well
// inside Q's band, falls period by period to the fixed point Q leaves, as ρ < 1 says it must.
TEST(ValveLearning, LearnsARepeatedErrorAwayOnAModelLoop) {
  const int n = 200;  // a 50 Hz sine
  ValveLawParams law = loop();
  law.proportional_a_per_m = law.integral_a_per_m_s = law.velocity_a_per_m_s = law.acceleration_a_per_m_s2 = 0.0;
  law.reference_velocity_a_per_m_s = law.reference_acceleration_a_per_m_s2 = law.reference_jerk_a_per_m_s3 = 0.0;
  // With no feedback and no inverse G is F·P·K_r: the reference filter and the valve, unit DC gain.
  const IdentifiedValve v = paper_like();
  const ValveLearningDesign d = design_valve_learning(v, law, n, valve_learning_settings());
  ASSERT_LT(d.convergence, 1.0);
  ValveLearning learning(n, d.delay_samples, d.filter, d.kernel);
  const double t = law.period_s, w0 = 2.0 * std::numbers::pi * v.natural_frequency_hz;
  const double wr = 2.0 * std::numbers::pi * law.reference_filter_hz;
  const int lag = static_cast<int>(std::lround((v.delay_s + 1.5 * t) / t));
  std::vector<double> command(static_cast<std::size_t>(lag + 1), 0.0);
  double f1 = 0, f2 = 0, f3 = 0, c = 0, x = 0, xd = 0;  // filter stages, lag, spool
  std::vector<double> worst;
  for (int k = 0; k < 30; ++k) {
    double peak = 0.0;
    for (int i = 0; i < n; ++i) {
      const double r = 1e-3 * std::sin(2.0 * std::numbers::pi * i / n);
      const double u = learning.update(r, x);
      if (k > 0) peak = std::max(peak, std::abs(learning.error()));
      f1 += t * wr * (r + u - f1);
      f2 += t * wr * (f1 - f2);
      f3 += t * wr * (f2 - f3);
      command.insert(command.begin(), f3);
      command.pop_back();
      for (int s = 0; s < 10; ++s) {  // the valve, in substeps
        c += t / 10 * (command.back() - c) / v.magnetic_lag_s;
        const double xdd = w0 * w0 * (c - x) - 2.0 * v.damping_ratio * w0 * xd;
        xd += t / 10 * xdd;
        x += t / 10 * xd;
      }
    }
    if (k > 0) worst.push_back(peak);
  }
  std::printf("  worst |e| per period [um]:");
  for (double e : worst) std::printf(" %.2f", e * 1e6);
  std::printf("\n");
  // A Q below 1 leaves a fixed point: at the sine's harmonic, with H·G = k_L·Q,
  // e∞/e0 = (1 − Q)/(1 − Q + k_L·Q) (about 5 % at 50 Hz for f_Q = 300 Hz). Allow the model's
  // discretisation a factor 2 on it.
  const double q = std::pow(2.0, -0.5 * std::pow(50.0 / valve_learning_settings().filter_hz, 2));
  const double fixed_point = (1.0 - q) / (1.0 - q + valve_learning_settings().gain * q);
  EXPECT_LT(worst.back(), 2.0 * fixed_point * worst.front()) << "the repeated error is learned down to Q's fixed point";
  for (std::size_t k = 1; k < worst.size(); ++k) EXPECT_LT(worst[k], worst[k - 1]) << "period " << k;
}

TEST(ValveLearning, UpdateDoesNotAllocate) {
  const ValveLearningDesign d = design_valve_learning(paper_like(), loop(), 1000, valve_learning_settings());
  ValveLearning learning(1000, d.delay_samples, d.filter, d.kernel);
  ValveLaw law(identified_valve_law(paper_like(), ValveLawStep::learning, 0.1));
  const long before = test::thread_allocations();
  for (int i = 0; i < 3000; ++i) {
    learning.update(1e-3 * std::sin(0.01 * i), 0.0, i % 7 == 0 ? 3 : 1);
    law.update(1e-3 * std::sin(0.01 * i), {});
  }
  EXPECT_EQ(test::thread_allocations(), before);
}

}  // namespace
}  // namespace hsa::control
