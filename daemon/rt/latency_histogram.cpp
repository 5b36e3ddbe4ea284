#include "daemon/rt/latency_histogram.hpp"

#include <bit>
#include <algorithm>
#include <cmath>
#include <limits>

namespace hsa::daemon {
namespace {

// Width of a quarter of the first octave: log bin edges are multiples of it, so the octave and
// sub-bin come from integer bit arithmetic instead of a logarithm.
constexpr std::int64_t kQuarterNs = LatencyHistogram::kLogStartNs / static_cast<std::int64_t>(LatencyHistogram::kSubBins);
static_assert(LatencyHistogram::kSubBins == 4, "bin_of's bit arithmetic assumes 4 sub-bins");

}  // namespace

std::size_t LatencyHistogram::bin_of(std::int64_t ns) noexcept {
  if (ns < kLogStartNs) {
    return ns <= 0 ? 0 : static_cast<std::size_t>(ns / kLinearBinNs);
  }
  if (ns >= kOverflowNs) {
    return kOverflowBin;
  }
  // x in [4 · 2^o, 8 · 2^o) for octave o; its top three bits are 1ss, ss the sub-bin.
  const auto x = static_cast<std::uint64_t>(ns / kQuarterNs);
  const auto octave = static_cast<std::size_t>(std::bit_width(x)) - 3;
  const auto sub = static_cast<std::size_t>(x >> octave) - kSubBins;
  return kLinearBins + octave * kSubBins + sub;
}

std::int64_t LatencyHistogram::lower_edge_ns(std::size_t bin) noexcept {
  if (bin < kLinearBins) {
    return static_cast<std::int64_t>(bin) * kLinearBinNs;
  }
  if (bin >= kOverflowBin) {
    return kOverflowNs;
  }
  const std::size_t octave = (bin - kLinearBins) / kSubBins;
  const std::size_t sub = (bin - kLinearBins) % kSubBins;
  return (kQuarterNs * static_cast<std::int64_t>(kSubBins + sub)) << octave;
}

std::int64_t LatencyHistogram::upper_edge_ns(std::size_t bin) noexcept {
  if (bin >= kOverflowBin) {
    return std::numeric_limits<std::int64_t>::max();
  }
  return lower_edge_ns(bin + 1);
}

std::int64_t histogram_percentile_ns(const LatencyHistogram::Counts& counts, double q) noexcept {
  std::uint64_t total = 0;
  for (const std::uint64_t c : counts) {
    total += c;
  }
  if (total == 0) {
    return 0;
  }
  // The rank (1-based) of the sample at quantile q: the smallest k with k ≥ q · total. The product
  // is shrunk by a relative 1e-12 first, so that rounding in q (0.999 is not exact in binary) cannot
  // push an exact rank like 999 of 1000 up to the next sample.
  const double exact = std::clamp(q, 0.0, 1.0) * static_cast<double>(total);
  const double wanted = std::ceil(exact - exact * 1e-12);
  const std::uint64_t rank = wanted < 1.0 ? 1 : static_cast<std::uint64_t>(wanted);
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < counts.size(); ++b) {
    seen += counts[b];
    if (seen >= rank) {
      return LatencyHistogram::lower_edge_ns(b);
    }
  }
  return LatencyHistogram::lower_edge_ns(LatencyHistogram::kOverflowBin);
}

Percentiles histogram_percentiles(const LatencyHistogram::Counts& counts) noexcept {
  return {histogram_percentile_ns(counts, 0.50), histogram_percentile_ns(counts, 0.99),
          histogram_percentile_ns(counts, 0.999)};
}

}  // namespace hsa::daemon
