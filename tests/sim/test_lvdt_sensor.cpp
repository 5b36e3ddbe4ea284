#include "sim/lvdt_sensor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace hsa::sim {
namespace {

constexpr double kPi = std::numbers::pi;

LvdtParameters quiet() {
  LvdtParameters p{};
  p.ripple_amplitude_m = {0.0, 0.0, 0.0};
  p.noise_density_m_per_sqrt_hz = 0.0;
  return p;
}

// The sensor of eq 7 itself, upstairs of the anti-aliasing filter.
TEST(LvdtSensor, StepResponseReachesSixtyThreePercentAfterTau) {
  const double dt = 1e-6;
  LvdtSensor lvdt(quiet(), dt);
  const double tau = 1.0 / (2.0 * kPi * 500.0);
  EXPECT_DOUBLE_EQ(lvdt.time_constant_s(), tau);
  double crossing = -1.0;
  for (int n = 1; n <= 2000; ++n) {
    lvdt.step(1e-3);
    if (lvdt.sensor_value() >= (1.0 - std::exp(-1.0)) * 1e-3) {
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
  EXPECT_LT(lvdt.sensor_value(), 0.632e-3);
  lvdt.step(1e-3);
  EXPECT_GT(lvdt.sensor_value(), 0.632e-3);
  // Downstairs, the anti-aliasing filter adds its group delay of about 0.2 ms: 2 more steps.
  LvdtSensor measured(quiet(), 1e-4);
  for (int n = 0; n < 5; ++n) {
    measured.step(1e-3);
  }
  EXPECT_LT(measured.value(), 0.632e-3);
  measured.step(1e-3);
  EXPECT_GT(measured.value(), 0.632e-3);
}

// The sensor bandwidth, as the loop sees it: the anti-aliasing filter takes 0.0001 dB more at
// 500 Hz.
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
  // Upstairs: density * sqrt(pi/2 * 500 Hz) = 1.12 um. Downstairs the anti-aliasing filter also
  // cuts the sensor filter's slow roll-off above 2 kHz: density * sqrt(integral of
  // |H_s|^2 |H_aa|^2 df) = 1.028 um (computed independently by quadrature). Both a few um, well
  // below the 10 um of eq 8.
  EXPECT_NEAR(lvdt.sensor_noise_rms(), 1.121e-6, 0.005e-6);
  EXPECT_NEAR(lvdt.noise_rms(), 1.028e-6, 0.002e-6);
  double sum = 0.0;
  double sum_sq = 0.0;
  double sensor_sum_sq = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    lvdt.step(0.0);
    sum += lvdt.value();
    sum_sq += lvdt.value() * lvdt.value();
    sensor_sum_sq += lvdt.sensor_value() * lvdt.sensor_value();
  }
  const double mean = sum / n;
  const double rms = std::sqrt(sum_sq / n);
  EXPECT_NEAR(mean, 0.0, 0.05e-6);
  EXPECT_NEAR(rms, lvdt.noise_rms(), 0.05 * lvdt.noise_rms());
  EXPECT_NEAR(std::sqrt(sensor_sum_sq / n), lvdt.sensor_noise_rms(), 0.05 * lvdt.sensor_noise_rms());

  p.anti_aliasing_order = 0;  // without the filter the loop reads the sensor's noise
  EXPECT_DOUBLE_EQ(LvdtSensor(p, 1e-4).noise_rms(), lvdt.sensor_noise_rms());
}

TEST(LvdtSensor, RippleIsTheFilteredExcitationHarmonics) {
  LvdtParameters p = quiet();
  p.ripple_amplitude_m = {20e-6, 10e-6, 5e-6};
  p.ripple_phase_rad = {0.3, 1.1, -0.7};
  const double dt = 1e-6;  // 200 samples per excitation period: no aliasing
  LvdtSensor lvdt(p, dt);

  double expected_sq = 0.0;
  double expected_peak = 0.0;
  double measured_sq = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double harmonic_hz = 5000.0 * static_cast<double>(k + 1);
    const double attenuation = std::hypot(1.0, 2.0 * kPi * harmonic_hz * lvdt.time_constant_s());
    EXPECT_NEAR(lvdt.ripple_amplitude(k), p.ripple_amplitude_m[k] / attenuation, 1e-12);
    EXPECT_NEAR(lvdt.measured_ripple_amplitude(k), lvdt.ripple_amplitude(k) * lvdt.anti_aliasing_gain(harmonic_hz),
                1e-15);
    expected_sq += 0.5 * lvdt.ripple_amplitude(k) * lvdt.ripple_amplitude(k);
    expected_peak += lvdt.ripple_amplitude(k);
    measured_sq += 0.5 * lvdt.measured_ripple_amplitude(k) * lvdt.measured_ripple_amplitude(k);
  }
  EXPECT_NEAR(lvdt.ripple_amplitude(0), 1.99e-6, 0.01e-6);

  for (int i = 0; i < 8000; ++i) {  // 8 ms: the anti-aliasing filter's transient dies out
    lvdt.step(0.0);
  }
  double sum_sq = 0.0;
  double measured_sum_sq = 0.0;
  double peak = 0.0;
  const int n = 2000;  // ten excitation periods
  for (int i = 0; i < n; ++i) {
    lvdt.step(0.0);
    sum_sq += lvdt.sensor_value() * lvdt.sensor_value();
    measured_sum_sq += lvdt.value() * lvdt.value();
    peak = std::max(peak, std::abs(lvdt.sensor_value()));
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), std::sqrt(expected_sq), 0.01e-6);
  EXPECT_LE(peak, expected_peak);
  EXPECT_GT(peak, 0.8 * expected_peak);
  // Downstairs: the same harmonics through the anti-aliasing filter, about 0.05 um in all.
  EXPECT_NEAR(std::sqrt(measured_sum_sq / n), std::sqrt(measured_sq), 0.05 * std::sqrt(measured_sq));
  EXPECT_LT(std::sqrt(measured_sum_sq / n), 0.05e-6);
}

// Without the anti-aliasing stage, the loop's 10 kHz sampling folds the ripple: 5 kHz and 15 kHz
// onto the Nyquist frequency (they alternate sign), 10 kHz onto DC. This was the simulated
// sensor before the stage was modelled, and the acceleration feedback turned it into chatter.
TEST(LvdtSensor, WithoutTheAntiAliasingFilterTheRippleAliasesAtTenKilohertz) {
  LvdtParameters p = quiet();
  p.ripple_amplitude_m = {20e-6, 10e-6, 5e-6};
  p.anti_aliasing_order = 0;
  LvdtSensor lvdt(p, 1e-4);
  EXPECT_EQ(lvdt.adc_samples_per_step(), 1);
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
  EXPECT_GT(std::abs(previous - dc), 1e-6);  // a Nyquist signal of about 2 um
}

// With it (section 2.3: 200 kHz sampling, then a digital anti-aliasing filter), what is left to
// fold is the ripple attenuated by the filter's designed stop-band gain: 4th-order Butterworth at
// 2 kHz, 1 / sqrt(1 + (5 / 2)^8) = -31.8 dB at 5 kHz and -55.9 dB at 10 kHz.
TEST(LvdtSensor, AntiAliasingFilterAttenuatesTheRippleBeforeTheTenKilohertzSampling) {
  LvdtParameters p = quiet();
  p.ripple_amplitude_m = {20e-6, 10e-6, 5e-6};
  LvdtSensor lvdt(p, 1e-4);
  EXPECT_EQ(lvdt.adc_samples_per_step(), 20);
  EXPECT_NEAR(20.0 * std::log10(lvdt.anti_aliasing_gain(5000.0)), -31.8, 0.1);
  EXPECT_NEAR(20.0 * std::log10(lvdt.anti_aliasing_gain(10000.0)), -55.9, 0.5);
  EXPECT_NEAR(lvdt.measured_ripple_amplitude(0) / lvdt.ripple_amplitude(0), lvdt.anti_aliasing_gain(5000.0), 1e-12);

  for (int i = 0; i < 100; ++i) {  // 10 ms: the filter's start-up transient dies out
    lvdt.step(0.0);
  }
  const double bound =
      lvdt.measured_ripple_amplitude(0) + lvdt.measured_ripple_amplitude(1) + lvdt.measured_ripple_amplitude(2);
  EXPECT_LT(bound, 0.07e-6);
  double lo = INFINITY;
  double hi = -INFINITY;
  for (int i = 0; i < 1000; ++i) {
    lvdt.step(0.0);
    EXPECT_LE(std::abs(lvdt.value()), bound);
    // The ripple still goes through the sensor's output (upstairs) untouched.
    EXPECT_LE(std::abs(lvdt.sensor_value()),
              lvdt.ripple_amplitude(0) + lvdt.ripple_amplitude(1) + lvdt.ripple_amplitude(2));
    lo = std::min(lo, lvdt.value());
    hi = std::max(hi, lvdt.value());
  }
  // The 5 kHz fold still alternates, at the attenuated amplitude: 2 um / 39 = 0.05 um.
  EXPECT_GT(hi - lo, 0.5 * lvdt.measured_ripple_amplitude(0));
}

// Amplitude and phase of the fundamental of y over whole periods (correlation).
struct Fundamental {
  double amplitude = 0.0;
  double phase_rad = 0.0;
};
Fundamental fundamental(const std::vector<double>& y, double frequency_hz, double dt) {
  double s = 0.0;
  double c = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double w = 2.0 * kPi * frequency_hz * static_cast<double>(k + 1) * dt;
    s += y[k] * std::sin(w);
    c += y[k] * std::cos(w);
  }
  const double n = static_cast<double>(y.size());
  return {2.0 / n * std::hypot(s, c), std::atan2(c, s)};
}

// "The low-frequency content is respected until 1 kHz, just above the sensor BW" (section 2.3):
// the anti-aliased measurement against the sensor's output, for a sine on the true position.
TEST(LvdtSensor, AntiAliasingFilterRespectsTheContentUpToOneKilohertzAndStopsTheExcitation) {
  const double dt = 1e-5;  // a 200 kHz ADC, 2 samples per step, and 20 steps per 5 kHz period
  for (double f : {10.0, 100.0, 500.0, 1000.0, 2000.0, 5000.0}) {
    SCOPED_TRACE(testing::Message() << f << " Hz");
    LvdtSensor lvdt(quiet(), dt);
    EXPECT_EQ(lvdt.adc_samples_per_step(), 2);
    const int period = static_cast<int>(std::lround(1.0 / (f * dt)));
    const int settle = std::max(1000, period);  // 10 ms, whole periods
    std::vector<double> measured;
    std::vector<double> sensor;
    for (int k = 0; k < settle + 2 * period; ++k) {
      lvdt.step(1e-3 * std::sin(2.0 * kPi * f * static_cast<double>(k) * dt));
      if (k >= settle - settle % period) {
        measured.push_back(lvdt.value());
        sensor.push_back(lvdt.sensor_value());
      }
    }
    const Fundamental m = fundamental(measured, f, dt);
    const Fundamental s = fundamental(sensor, f, dt);
    const double gain_db = 20.0 * std::log10(m.amplitude / s.amplitude);
    // 0.1 dB: at 5 kHz the sensor's 100 kHz samples also hold a little of the ADC's 95 kHz image.
    EXPECT_NEAR(gain_db, 20.0 * std::log10(lvdt.anti_aliasing_gain(f)), 0.1);
    if (f <= 1000.0) {
      EXPECT_GT(gain_db, -0.1);  // respected
      EXPECT_LT(gain_db, 0.01);
    }
    if (f == 2000.0) {
      EXPECT_NEAR(gain_db, -3.0, 0.1);  // the cut-off
    }
    if (f == 5000.0) {
      EXPECT_LT(gain_db, -30.0);  // the excitation
    }
    if (f == 100.0) {
      // A Butterworth's group delay at low frequency: about 2.61 / (2 pi 2 kHz) = 0.21 ms.
      double lag = s.phase_rad - m.phase_rad;
      if (lag < 0.0) lag += 2.0 * kPi;
      EXPECT_NEAR(lag / (2.0 * kPi * f), 0.21e-3, 0.02e-3);
    }
  }
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

TEST(LvdtSensor, RejectsAnAntiAliasingFilterItCannotBuild) {
  LvdtParameters odd;
  odd.anti_aliasing_order = 3;
  EXPECT_THROW(LvdtSensor(odd, 1e-4), std::invalid_argument);
  LvdtParameters high;
  high.anti_aliasing_order = 10;
  EXPECT_THROW(LvdtSensor(high, 1e-4), std::invalid_argument);
  LvdtParameters fast;
  fast.anti_aliasing_hz = 60e3;  // above a quarter of 200 kHz
  EXPECT_THROW(LvdtSensor(fast, 1e-4), std::invalid_argument);
}

}  // namespace
}  // namespace hsa::sim
