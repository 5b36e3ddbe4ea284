#include "sim/lvdt_sensor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::sim {
namespace {

constexpr double kPi = std::numbers::pi;

LvdtParameters quiet() {
  LvdtParameters p{};
  p.ripple_amplitude_m = {0.0, 0.0, 0.0};
  p.noise_density_m_per_sqrt_hz = 0.0;
  return p;
}

TEST(LvdtSensor, StepResponseReachesSixtyThreePercentAfterTau) {
  const double dt = 1e-6;
  LvdtSensor lvdt(quiet(), dt);
  const double tau = 1.0 / (2.0 * kPi * 500.0);
  EXPECT_DOUBLE_EQ(lvdt.time_constant_s(), tau);
  double crossing = -1.0;
  for (int n = 1; n <= 2000; ++n) {
    lvdt.step(1e-3);
    if (lvdt.value() >= (1.0 - std::exp(-1.0)) * 1e-3) {
      crossing = n * dt;
      break;
    }
  }
  EXPECT_NEAR(crossing, tau, 2e-6);
}

TEST(LvdtSensor, StepResponseAtTheRigStep) {
  LvdtSensor lvdt(quiet(), 1e-4);  // tau = 0.318 ms: 63 % is passed between the 3rd and 4th step
  for (int n = 0; n < 3; ++n) {
    lvdt.step(1e-3);
  }
  EXPECT_LT(lvdt.value(), 0.632e-3);
  lvdt.step(1e-3);
  EXPECT_GT(lvdt.value(), 0.632e-3);
}

TEST(LvdtSensor, MinusThreeDecibelsAtFiveHundredHertz) {
  const double dt = 1e-6;
  LvdtSensor lvdt(quiet(), dt);
  double peak = 0.0;
  for (int n = 0; n < 20000; ++n) {  // 10 periods; keep the last 5, after the transient
    lvdt.step(1e-3 * std::sin(2.0 * kPi * 500.0 * n * dt));
    if (n >= 10000) {
      peak = std::max(peak, lvdt.value());
    }
  }
  EXPECT_NEAR(peak / 1e-3, 1.0 / std::sqrt(2.0), 0.005);
}

TEST(LvdtSensor, NoiseRmsMatchesTheDensity) {
  LvdtParameters p = quiet();
  p.noise_density_m_per_sqrt_hz = 0.04e-6;
  LvdtSensor lvdt(p, 1e-4);
  // density * sqrt(pi/2 * 500 Hz) = 1.12 um: a few um, well below the 10 um of eq 8
  EXPECT_NEAR(lvdt.noise_rms(), 1.121e-6, 0.005e-6);
  double sum = 0.0;
  double sum_sq = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    lvdt.step(0.0);
    sum += lvdt.value();
    sum_sq += lvdt.value() * lvdt.value();
  }
  const double mean = sum / n;
  const double rms = std::sqrt(sum_sq / n);
  EXPECT_NEAR(mean, 0.0, 0.05e-6);
  EXPECT_NEAR(rms, lvdt.noise_rms(), 0.05 * lvdt.noise_rms());
}

TEST(LvdtSensor, RippleIsTheFilteredExcitationHarmonics) {
  LvdtParameters p = quiet();
  p.ripple_amplitude_m = {20e-6, 10e-6, 5e-6};
  p.ripple_phase_rad = {0.3, 1.1, -0.7};
  const double dt = 1e-6;  // 200 samples per excitation period: no aliasing
  LvdtSensor lvdt(p, dt);

  double expected_sq = 0.0;
  double expected_peak = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double harmonic_hz = 5000.0 * static_cast<double>(k + 1);
    const double attenuation = std::hypot(1.0, 2.0 * kPi * harmonic_hz * lvdt.time_constant_s());
    EXPECT_NEAR(lvdt.ripple_amplitude(k), p.ripple_amplitude_m[k] / attenuation, 1e-12);
    expected_sq += 0.5 * lvdt.ripple_amplitude(k) * lvdt.ripple_amplitude(k);
    expected_peak += lvdt.ripple_amplitude(k);
  }
  EXPECT_NEAR(lvdt.ripple_amplitude(0), 1.99e-6, 0.01e-6);

  double sum_sq = 0.0;
  double peak = 0.0;
  const int n = 2000;  // ten excitation periods
  for (int i = 0; i < n; ++i) {
    lvdt.step(0.0);
    sum_sq += lvdt.value() * lvdt.value();
    peak = std::max(peak, std::abs(lvdt.value()));
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), std::sqrt(expected_sq), 0.01e-6);
  EXPECT_LE(peak, expected_peak);
  EXPECT_GT(peak, 0.8 * expected_peak);
}

TEST(LvdtSensor, RippleAliasesWhenSampledAtTenKilohertz) {
  LvdtParameters p = quiet();
  p.ripple_amplitude_m = {20e-6, 10e-6, 5e-6};
  LvdtSensor lvdt(p, 1e-4);
  // 5 kHz and 15 kHz fold onto the Nyquist frequency (they alternate sign), 10 kHz onto DC.
  const double omega_tau = 2.0 * kPi * 10000.0 * lvdt.time_constant_s();
  const double dc = lvdt.ripple_amplitude(1) * std::sin(-std::atan(omega_tau));
  double sum = 0.0;
  double previous = 0.0;
  int alternations = 0;
  for (int i = 0; i < 1000; ++i) {
    lvdt.step(0.0);
    sum += lvdt.value();
    alternations += (i > 0 && (lvdt.value() - dc) * (previous - dc) < 0.0) ? 1 : 0;
    previous = lvdt.value();
    EXPECT_LE(std::abs(lvdt.value()),
              lvdt.ripple_amplitude(0) + lvdt.ripple_amplitude(1) + lvdt.ripple_amplitude(2));
  }
  EXPECT_NEAR(sum / 1000.0, dc, 1e-12);
  EXPECT_EQ(alternations, 999);
}

TEST(LvdtSensor, DefaultErrorStaysWithinTheResidualRequirement) {
  LvdtSensor lvdt({}, 1e-4);
  LvdtSensor ideal(quiet(), 1e-4);  // the same filter without ripple and noise: leaves out the lag
  double worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const double x = 1e-3 * std::sin(2.0 * kPi * 20.0 * i * 1e-4);
    lvdt.step(x);
    ideal.step(x);
    worst = std::max(worst, std::abs(lvdt.value() - ideal.value()));
  }
  EXPECT_LT(worst, 10e-6);
  EXPECT_GT(worst, 2e-6);  // but there is an error
}

TEST(LvdtSensor, BiasAndScaleFactorErrorAreApplied) {
  LvdtParameters p = quiet();
  p.bias_m = 5e-6;
  p.scale_factor_error = 0.02;
  LvdtSensor lvdt(p, 1e-4);
  for (int i = 0; i < 200; ++i) {  // 20 ms, 60 time constants
    lvdt.step(1e-3);
  }
  EXPECT_NEAR(lvdt.value(), 1.02e-3 + 5e-6, 1e-12);
  EXPECT_NEAR(lvdt.voltage(), 3300.0 * (1.02e-3 + 5e-6), 1e-9);
  EXPECT_FALSE(lvdt.saturated());
}

TEST(LvdtSensor, SaturatesAtTheOutputRange) {
  LvdtSensor lvdt(quiet(), 1e-4);
  lvdt.reset(5e-3);
  EXPECT_TRUE(lvdt.saturated());
  EXPECT_DOUBLE_EQ(lvdt.voltage(), 10.0);
  EXPECT_DOUBLE_EQ(lvdt.value(), 10.0 / 3300.0);
  lvdt.reset(-2.5e-3);  // the valve's rest stop is inside the range
  EXPECT_FALSE(lvdt.saturated());
  EXPECT_DOUBLE_EQ(lvdt.value(), -2.5e-3);
  for (int i = 0; i < 100; ++i) {
    lvdt.step(-4e-3);
  }
  EXPECT_TRUE(lvdt.saturated());
  EXPECT_DOUBLE_EQ(lvdt.value(), -10.0 / 3300.0);
}

TEST(LvdtSensor, SameSeedSameNoiseOtherSeedOtherNoise) {
  LvdtParameters p{};
  p.seed = 7;
  LvdtSensor a(p, 1e-4);
  LvdtSensor b(p, 1e-4);
  p.seed = 8;
  LvdtSensor c(p, 1e-4);
  int differing = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = 1e-3 * std::sin(0.01 * i);
    a.step(x);
    b.step(x);
    c.step(x);
    ASSERT_EQ(a.value(), b.value()) << "step " << i;
    differing += a.value() != c.value() ? 1 : 0;
  }
  EXPECT_GT(differing, 990);

  a.reset(0.0);  // reset restarts the random sequence and the excitation phase
  LvdtSensor fresh(a.parameters(), 1e-4);
  for (int i = 0; i < 100; ++i) {
    a.step(1e-4);
    fresh.step(1e-4);
    ASSERT_EQ(a.value(), fresh.value());
  }
}

TEST(LvdtSensor, RejectsANonPositiveStep) {
  EXPECT_THROW(LvdtSensor({}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::sim
