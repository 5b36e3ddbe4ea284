#include "daemon/rt/latency_histogram.hpp"

#include <gtest/gtest.h>

namespace hsa::daemon {
namespace {

using H = LatencyHistogram;

TEST(LatencyHistogram, MicrosecondBinsBelowOneMillisecond) {
  EXPECT_EQ(H::bin_of(-5), 0U);
  EXPECT_EQ(H::bin_of(0), 0U);
  EXPECT_EQ(H::bin_of(999), 0U);
  EXPECT_EQ(H::bin_of(1'000), 1U);
  EXPECT_EQ(H::bin_of(4'700), 4U);
  EXPECT_EQ(H::bin_of(999'999), 999U);
  EXPECT_EQ(H::lower_edge_ns(4), 4'000);
  EXPECT_EQ(H::upper_edge_ns(4), 5'000);
}

TEST(LatencyHistogram, QuarterOctaveBinsFromOneMillisecondToOneSecond) {
  EXPECT_EQ(H::bin_of(1'000'000), 1000U);
  EXPECT_EQ(H::bin_of(1'249'999), 1000U);
  EXPECT_EQ(H::bin_of(1'250'000), 1001U);
  EXPECT_EQ(H::bin_of(1'999'999), 1003U);
  EXPECT_EQ(H::bin_of(2'000'000), 1004U);
  EXPECT_EQ(H::bin_of(100'000'000), H::bin_of(96'000'000));  // 100 ms lies in [96, 112) ms
  EXPECT_EQ(H::lower_edge_ns(H::bin_of(100'000'000)), 96'000'000);
  EXPECT_EQ(H::bin_of(1'023'999'999), H::kOverflowBin - 1);
  EXPECT_EQ(H::bin_of(1'024'000'000), H::kOverflowBin);
  EXPECT_EQ(H::bin_of(INT64_MAX), H::kOverflowBin);
}

TEST(LatencyHistogram, EveryValueLiesInItsBinAndBinsTile) {
  for (std::size_t b = 0; b + 1 < H::kBins; ++b) {
    EXPECT_EQ(H::upper_edge_ns(b), H::lower_edge_ns(b + 1)) << b;
    EXPECT_LT(H::lower_edge_ns(b), H::upper_edge_ns(b)) << b;
    EXPECT_EQ(H::bin_of(H::lower_edge_ns(b)), b) << b;
    EXPECT_EQ(H::bin_of(H::upper_edge_ns(b) - 1), b) << b;
  }
  EXPECT_EQ(H::lower_edge_ns(H::kOverflowBin), H::kOverflowNs);
}

TEST(HistogramPercentile, EmptyIsZero) {
  const H::Counts counts{};
  EXPECT_EQ(histogram_percentile_ns(counts, 0.99), 0);
}

TEST(HistogramPercentile, ReportsTheLowerEdgeOfTheBinHoldingTheRank) {
  H::Counts counts{};
  counts[H::bin_of(4'300)] = 900;      // 4 µs
  counts[H::bin_of(11'200)] = 90;      // 11 µs
  counts[H::bin_of(40'000)] = 9;       // 40 µs
  counts[H::bin_of(2'100'000)] = 1;    // 2 ms
  EXPECT_EQ(histogram_percentile_ns(counts, 0.0), 4'000);
  EXPECT_EQ(histogram_percentile_ns(counts, 0.50), 4'000);
  EXPECT_EQ(histogram_percentile_ns(counts, 0.90), 4'000);    // rank 900: still the 4 µs bin
  EXPECT_EQ(histogram_percentile_ns(counts, 0.901), 11'000);  // rank 901
  EXPECT_EQ(histogram_percentile_ns(counts, 0.99), 11'000);
  EXPECT_EQ(histogram_percentile_ns(counts, 0.999), 40'000);
  EXPECT_EQ(histogram_percentile_ns(counts, 1.0), 2'000'000);
  const Percentiles p = histogram_percentiles(counts);
  EXPECT_EQ(p.p50_ns, 4'000);
  EXPECT_EQ(p.p99_ns, 11'000);
  EXPECT_EQ(p.p999_ns, 40'000);
}

}  // namespace
}  // namespace hsa::daemon
