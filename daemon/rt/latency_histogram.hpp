#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace hsa::daemon {

// Fixed bin layout for wakeup lateness and execution time, so the RT thread only increments a
// counter in a preallocated array (no allocation, no search):
//   - 1000 linear bins of 1 µs covering [0, 1 ms): where a healthy loop lives, and the same 1 µs
//     resolution cyclictest reports in, so the two compare bin for bin;
//   - 40 log bins covering [1 ms, 1.024 s): 10 octaves of 4 equal sub-bins each (≤ 25 % wide),
//     enough to tell a 2 ms scheduler hiccup from a 100 ms VM pause;
//   - one overflow bin for ≥ 1.024 s.
// Negative values (impossible for lateness with TIMER_ABSTIME, but cheap to guard) land in bin 0.
struct LatencyHistogram {
  static constexpr std::size_t kLinearBins = 1000;
  static constexpr std::int64_t kLinearBinNs = 1000;
  static constexpr std::size_t kOctaves = 10;
  static constexpr std::size_t kSubBins = 4;
  static constexpr std::size_t kLogBins = kOctaves * kSubBins;
  static constexpr std::size_t kBins = kLinearBins + kLogBins + 1;
  static constexpr std::size_t kOverflowBin = kBins - 1;
  static constexpr std::int64_t kLogStartNs = static_cast<std::int64_t>(kLinearBins) * kLinearBinNs;
  static constexpr std::int64_t kOverflowNs = kLogStartNs << kOctaves;  // 1.024 s

  using Counts = std::array<std::uint64_t, kBins>;

  [[nodiscard]] static std::size_t bin_of(std::int64_t ns) noexcept;
  // [lower_edge_ns(b), upper_edge_ns(b)) is the range of bin b; the overflow bin has no upper edge
  // and reports INT64_MAX.
  [[nodiscard]] static std::int64_t lower_edge_ns(std::size_t bin) noexcept;
  [[nodiscard]] static std::int64_t upper_edge_ns(std::size_t bin) noexcept;
};

// The q-quantile (q in [0, 1], e.g. 0.99) of the values counted in a histogram, as the lower edge of
// the bin that holds it: in the 1 µs range that is the value truncated to whole µs, which is how
// cyclictest reports, so ratios against it are fair. 0 for an empty histogram.
[[nodiscard]] std::int64_t histogram_percentile_ns(const LatencyHistogram::Counts& counts, double q) noexcept;

// The three percentiles the reports use.
struct Percentiles {
  std::int64_t p50_ns = 0;
  std::int64_t p99_ns = 0;
  std::int64_t p999_ns = 0;
};
[[nodiscard]] Percentiles histogram_percentiles(const LatencyHistogram::Counts& counts) noexcept;

}  // namespace hsa::daemon
