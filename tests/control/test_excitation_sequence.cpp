#include "control/excitation_sequence.hpp"

#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

std::vector<double> samples(ExcitationSequence& s, std::size_t n) {
  std::vector<double> v(n);
  for (double& x : v) x = s.next();
  return v;
}

// Indices where the value changes.
std::vector<std::size_t> changes(const std::vector<double>& v) {
  std::vector<std::size_t> at;
  for (std::size_t k = 1; k < v.size(); ++k)
    if (v[k] != v[k - 1]) at.push_back(k);
  return at;
}

TEST(ExcitationSequence, PrmsTakesOnlyItsEvenlySpacedLevelsAndUsesThemAll) {
  ExcitationSequence s({.kind = ExcitationKind::prms, .amplitude = 2e-3, .switching_time_s = 0.05, .levels = 5});
  std::map<double, int> seen;
  for (double x : samples(s, 50000)) ++seen[x];
  ASSERT_EQ(seen.size(), 5u);
  const double expected[] = {-2e-3, -1e-3, 0.0, 1e-3, 2e-3};
  int k = 0;
  for (const auto& [level, count] : seen) {
    EXPECT_NEAR(level, expected[k++], 1e-15);
    // 1000 switches over 5 levels: about 200 each (binomial σ ≈ 13).
    EXPECT_GT(count / 50, 140);
    EXPECT_LT(count / 50, 260);
  }
}

TEST(ExcitationSequence, ChangesOnlyAtWholeSwitchingTimes) {
  ExcitationSequence prbs({.kind = ExcitationKind::prbs, .amplitude = 1.0, .switching_time_s = 0.02});
  const auto v = samples(prbs, 20000);
  for (double x : v) EXPECT_EQ(std::abs(x), 1.0);
  const auto at = changes(v);
  ASSERT_GT(at.size(), 300u);  // about half of the 1000 bits change the value
  for (std::size_t k : at) EXPECT_EQ(k % 20, 0u) << k;

  // Random widths: 1…4 switching times, each width used.
  ExcitationSequence prms({.amplitude = 1.0, .switching_time_s = 0.01, .levels = 7, .max_hold_switches = 4});
  const auto w = samples(prms, 40000);
  std::set<std::size_t> widths;
  std::size_t last = 0;
  for (std::size_t k : changes(w)) {
    EXPECT_EQ(k % 10, 0u);
    widths.insert(k - last);
    last = k;
  }
  // A level may be drawn twice in a row, so a width can be a sum of holds; 10…40 samples must all occur.
  for (std::size_t width : {10u, 20u, 30u, 40u}) EXPECT_TRUE(widths.count(width)) << width;
}

TEST(ExcitationSequence, SameSeedSameSequenceOtherSeedAnother) {
  const ExcitationParams p{.amplitude = 1.0, .switching_time_s = 0.01, .levels = 4, .seed = 42};
  ExcitationSequence a(p), b(p);
  const auto va = samples(a, 5000);
  EXPECT_EQ(va, samples(b, 5000));
  a.reset();
  EXPECT_EQ(va, samples(a, 5000));
  ExcitationParams q = p;
  q.seed = 43;
  ExcitationSequence c(q);
  EXPECT_NE(va, samples(c, 5000));
}

// Mean power in a band of the periodogram of the zero-mean sequence, averaged over segments.
double band_power(const std::vector<double>& v, double period_s, double f_lo, double f_hi) {
  const std::size_t n = 1024;
  double power = 0.0;
  int count = 0;
  for (std::size_t start = 0; start + n <= v.size(); start += n) {
    for (std::size_t bin = 1; bin < n / 2; ++bin) {
      const double f = bin / (n * period_s);
      if (f < f_lo || f > f_hi) continue;
      std::complex<double> sum = 0.0;
      for (std::size_t k = 0; k < n; ++k)
        sum += v[start + k] * std::polar(1.0, -2.0 * std::numbers::pi * bin * k / n);
      power += std::norm(sum);
      ++count;
    }
  }
  return power / count;
}

// A random telegraph signal switching every T has the spectrum sinc²(f·T): flat at low
// frequency, −3.9 dB at 1/(2T), a null at 1/T. Both kinds must keep their power up to 1/(2T).
TEST(ExcitationSequence, SpectrumIsRoughlyFlatUpToHalfTheSwitchingRate) {
  for (ExcitationKind kind : {ExcitationKind::prms, ExcitationKind::prbs}) {
    ExcitationSequence s({.kind = kind, .amplitude = 1.0, .switching_time_s = 0.01, .levels = 6, .seed = 7});
    auto v = samples(s, 1024 * 24);
    double mean = 0.0;
    for (double x : v) mean += x / v.size();
    for (double& x : v) x -= mean;
    const double low = band_power(v, 1e-3, 2.0, 10.0);
    const double half = band_power(v, 1e-3, 45.0, 50.0);  // just below 1/(2T) = 50 Hz
    const double null = band_power(v, 1e-3, 98.0, 102.0);  // around 1/T
    EXPECT_GT(half / low, std::pow(10.0, -5.0 / 10.0)) << "more than 5 dB down at 1/(2T)";
    EXPECT_LT(null / low, 0.05) << "no null at 1/T";
  }
}

TEST(ExcitationSequence, NextAllocatesNothing) {
  ExcitationSequence s({.amplitude = 1.0, .switching_time_s = 0.002, .levels = 9, .max_hold_switches = 3});
  const long before = test::thread_allocations();
  double sum = 0.0;
  for (int k = 0; k < 10000; ++k) sum += s.next();
  s.reset();
  EXPECT_EQ(test::thread_allocations(), before);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(ExcitationSequence, RefusesParametersThatMakeNoSequence) {
  EXPECT_THROW(ExcitationSequence({.amplitude = -1.0}), std::invalid_argument);
  EXPECT_THROW(ExcitationSequence({.switching_time_s = 1e-4}), std::invalid_argument);
  EXPECT_THROW(ExcitationSequence({.levels = 1}), std::invalid_argument);
  EXPECT_THROW(ExcitationSequence({.max_hold_switches = 0}), std::invalid_argument);
  EXPECT_NO_THROW(ExcitationSequence({.kind = ExcitationKind::prbs, .levels = 1}));
}

}  // namespace
}  // namespace hsa::control
