#include "control/valve_law.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace hsa::control {
namespace {

constexpr double kExact = 1e-12;  // a few roundings on currents of order 1 A

// Illustrative SI gains of the order the paper's analogue controller implies (Table 1 with
// K_s = 3.3 V/mm and R = 4 Ω: K_r·K_s/R ≈ 250 A/m, k_p·K_s/R ≈ 3300 A/m for k_p = 4). Every
// test derives its expectations from these numbers, not from the values below.
ValveLawParams example() {
  ValveLawParams p;
  p.bias_current_a = 1.2;
  p.max_current_a = 3.0;
  p.feedforward_a_per_m = 250.0;
  p.integral_a_per_m_s = 5e4;
  p.proportional_a_per_m = 3300.0;
  p.dead_band_compensation_a = 0.15;  // half of the 0.3 A hysteresis dead band of Canuto et al. (2014), eq 6
  p.dead_band_error_m = 5e-6;
  p.velocity_a_per_m_s = 2.0;
  p.acceleration_a_per_m_s2 = 1e-3;
  return p;
}

TEST(ValveLaw, OutputsTheBiasAtZeroErrorAtHydraulicZero) {
  ValveLaw law(example());
  for (int k = 0; k < 10; ++k) EXPECT_EQ(law.update(0.0, {}), 1.2);
  EXPECT_EQ(law.integral(), 0.0);
  EXPECT_FALSE(law.saturated());
}

TEST(ValveLaw, EachTermActsWithItsGainAndSign) {
  const ValveLawParams p = example();
  {
    ValveLaw law(p);  // feedforward with the spool on the reference
    EXPECT_NEAR(law.update(1e-3, {.position_m = 1e-3}), 1.2 + 250.0 * 1e-3, kExact);
  }
  {
    ValveLaw law(p);  // velocity and acceleration damp
    EXPECT_NEAR(law.update(0.0, {.velocity_m_s = 0.1}), 1.2 - 0.2, kExact);
    EXPECT_NEAR(law.update(0.0, {.acceleration_m_s2 = 200.0}), 1.2 - 0.2, kExact);
  }
  {
    ValveLaw law(p);  // a positive error raises the current, now and through the integral
    const double e = 1e-5;  // reference e, spool at 0
    const double first = law.update(e, {});
    EXPECT_NEAR(first, 1.2 + 250.0 * e + law.error_function(e), kExact) << "eq 31 integrates after the output";
    EXPECT_GT(law.error_function(e), 0.0);
    EXPECT_NEAR(law.integral(), 1e-4 * e, kExact);
    EXPECT_NEAR(law.update(e, {}), first + 5e4 * 1e-4 * e, kExact);
  }
}

TEST(ValveLaw, ErrorFunctionIsOddSmoothMonotonicAndSteepestAtZero) {
  const ValveLaw law(example());
  const double kp = 3300.0, di = 0.15, ew = 5e-6;
  double previous = law.error_function(-5e-3);
  for (double e = -5e-3 + 1e-7; e <= 5e-3; e += 1e-7) {
    const double value = law.error_function(e);
    EXPECT_GT(value, previous) << "at e = " << e;
    EXPECT_NEAR(law.error_function(-e), -value, kExact);
    previous = value;
  }
  // Central differences: the slope is kp + ΔI/e_w at zero and tends to kp far from it. The
  // second derivative is O(ΔI/e_w³), so steps of e_w/1000 leave a relative error below 1e-6.
  const double h = ew * 1e-3;
  const auto slope = [&](double e) { return (law.error_function(e + h) - law.error_function(e - h)) / (2 * h); };
  EXPECT_NEAR(slope(0.0), kp + di / ew, 1e-6 * (kp + di / ew));
  EXPECT_NEAR(slope(20 * ew), kp, 1e-6 * kp);  // sech²(20) ≈ 2e-17
  EXPECT_GT(slope(0.0), 5.0 * slope(5 * ew));
  // The dead-band inversion adds at most ±ΔI on top of the linear part.
  EXPECT_NEAR(law.error_function(1e-3) - kp * 1e-3, di, 1e-12);
}

TEST(ValveLaw, ClampsToZeroAndImaxWithAntiWindup) {
  for (const double sign : {1.0, -1.0}) {
    ValveLaw law(example());
    const double big = sign * 1e-3;  // k_p·1 mm = 3.3 A beyond the bias: saturates both ways
    for (int k = 0; k < 1000; ++k) law.update(big, {});
    EXPECT_EQ(law.current(), sign > 0 ? 3.0 : 0.0);
    EXPECT_TRUE(law.saturated());
    EXPECT_EQ(law.saturation_count(), 1000u);
    EXPECT_EQ(law.integral(), 0.0) << "the integrator must not wind up against the clamp";

    // A small error of the other sign brings the current back inside at once.
    const double small = -sign * 1e-6;
    const double current = law.update(small, {});
    EXPECT_NEAR(current, 1.2 + 250.0 * small + law.error_function(small), kExact);
    EXPECT_FALSE(law.saturated());
  }
}

TEST(ValveLaw, IntegratorStillUnwindsWhileClampedTheOtherWay) {
  ValveLaw law(example());
  law.reset(1e-4);  // K_i·s = 5 A: clamped at I_max by the integral alone
  const double e = -1e-7;  // small: 1.2 + 5 + K_p(e) ≫ 3 A, still clamped
  law.update(e, {});
  EXPECT_TRUE(law.saturated());
  EXPECT_NEAR(law.integral(), 1e-4 + 1e-4 * e, kExact);
}

TEST(ValveLaw, DitherIsASquareWaveOfWholeSamplesAroundTheLaw) {
  ValveLawParams p = example();
  p.dither_amplitude_a = 0.2;
  p.dither_frequency_hz = 1000.0;  // 10 samples per period at 10 kHz: 5 high, 5 low
  ValveLaw law(p);
  double sum = 0.0;
  for (int k = 0; k < 20; ++k) {
    const double current = law.update(0.0, {});
    EXPECT_NEAR(current, (k % 10) < 5 ? 1.4 : 1.0, kExact) << "sample " << k;
    sum += current - 1.2;
  }
  EXPECT_NEAR(sum, 0.0, kExact) << "the dither must not shift the mean current";
  EXPECT_EQ(law.integral(), 0.0);
}

// Near a limit the dithered output clips, but the law itself is not saturated: no count, and the
// integrator keeps integrating.
TEST(ValveLaw, DitherClippedAtALimitIsNotSaturation) {
  ValveLawParams p = example();
  p.bias_current_a = 2.9;
  p.dither_amplitude_a = 0.2;
  p.dither_frequency_hz = 1000.0;
  ValveLaw law(p);
  const double e = 1e-8;  // keeps the law just above 2.9 A
  EXPECT_EQ(law.update(e, {}), 3.0);
  EXPECT_FALSE(law.saturated());
  EXPECT_EQ(law.saturation_count(), 0u);
  EXPECT_NEAR(law.integral(), 1e-4 * e, kExact);
}

// Skipped samples: with the error held, the integral after the same span is the same whether
// every sample ran or only some did (the catch-up adds (m − 1)·T·e of the held error), and the
// dither's phase follows the elapsed samples.
TEST(ValveLaw, SkippedSamplesIntegrateTheHeldErrorOverTheElapsedTime) {
  ValveLawParams p = example();
  p.dither_amplitude_a = 0.1;
  p.dither_frequency_hz = 1250.0;  // half period: 4 samples
  const double r = 2e-6;           // small: no clamp, the integrator runs every sample
  const PredictorOutput at_rest{};
  ValveLaw every(p), skipping(p);
  double last_every = 0.0;
  for (int i = 0; i <= 1000; ++i) last_every = every.update(r, at_rest);
  double last_skipping = 0.0;
  int updates = 0;
  for (int i = 0, previous = 0, jump = 1; i <= 1000; previous = i, i = i < 1000 ? std::min(i + jump, 1000) : 1001,
           jump = jump % 23 + 5) {
    const std::uint64_t elapsed = i == 0 ? 1 : static_cast<std::uint64_t>(i - previous);
    last_skipping = skipping.update(r, at_rest, elapsed);
    ++updates;
  }
  ASSERT_LT(updates, 200);
  // 1001 samples of T·r; rounding of the sums (n·ε·|s|, n ≤ 1001 terms each side).
  const double integral = 1001 * p.period_s * r;
  const double tol = 2 * 1001 * std::numeric_limits<double>::epsilon() * integral;
  EXPECT_NEAR(every.integral(), integral, tol);
  EXPECT_NEAR(skipping.integral(), every.integral(), tol);
  // Same sample index 1000: the same dither phase, so the same output to within the integral's
  // rounding times K_i.
  EXPECT_NEAR(last_skipping, last_every, p.integral_a_per_m_s * tol + kExact);
}

TEST(ValveLaw, RejectsInvalidParameters) {
  auto with = [](auto change) {
    ValveLawParams p = example();
    change(p);
    return p;
  };
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.period_s = 0.0; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.max_current_a = 0.0; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.bias_current_a = 3.5; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.dead_band_error_m = 0.0; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.velocity_a_per_m_s = -1.0; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.integral_a_per_m_s = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.dither_amplitude_a = -0.1; })), std::invalid_argument);
  EXPECT_THROW(ValveLaw(with([](ValveLawParams& p) { p.dither_amplitude_a = 1.6; })), std::invalid_argument);
  // 3 kHz is 3.33 samples per half period at 10 kHz; 0 Hz or 6 kHz has no whole half period.
  for (double f : {3000.0, 0.0, 6000.0, std::nan("")}) {
    EXPECT_THROW(ValveLaw(with([f](ValveLawParams& p) {
                   p.dither_amplitude_a = 0.1;
                   p.dither_frequency_hz = f;
                 })),
                 std::invalid_argument)
        << f << " Hz";
  }
  EXPECT_NO_THROW(ValveLaw(with([](ValveLawParams& p) {
    p.dither_amplitude_a = 0.1;
    p.dither_frequency_hz = 5000.0;
  })));
}

}  // namespace
}  // namespace hsa::control
