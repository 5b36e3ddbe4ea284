#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>

#include "daemon/rt/latency_histogram.hpp"
#include "daemon/rt/rt_stats.hpp"

namespace hsa::daemon {

// Cumulative counts of the things the steady-state cycle must not do, as read on the RT thread:
// its own page faults (getrusage RUSAGE_THREAD) and the process-wide RT-flagged allocation and
// lock counters (rt_counters.hpp).
struct SteadyStateCounts {
  std::uint64_t minor_faults = 0;
  std::uint64_t major_faults = 0;
  std::uint64_t allocations = 0;
  std::uint64_t deallocations = 0;
  std::uint64_t locks = 0;
};

// What the executive measured in one cycle.
struct CycleSample {
  std::int64_t lateness_ns = 0;   // woke − scheduled
  std::int64_t execution_ns = 0;  // end − woke
  std::uint64_t skipped = 0;      // periods skipped after this cycle; > 0 means it overran
  // Read at the end of the cycle when RtStatsRecorder::counts_due() said so; empty otherwise.
  std::optional<SteadyStateCounts> counts;
};

// The RT loop's statistics: written by the RT thread only, read by any thread without a lock.
//
// Design: a seqlock over atomics. The single writer makes the sequence number odd, updates
// the fields, and makes it even again; a reader copies everything and retries if the number was
// odd or changed, so a snapshot is consistent (the histogram counts sum to the cycle count) and the
// writer never waits. Every field is an atomic so the concurrent copy is not a data race. The
// histogram arrays are members, allocated with the recorder before the RT thread starts, so
// record() allocates nothing and touches only memory that is already there.
class RtStatsRecorder {
 public:
  explicit RtStatsRecorder(std::uint64_t warmup_cycles) noexcept;

  // RT thread, once, before the first cycle: the baseline of the cumulative counts.
  void begin(const SteadyStateCounts& counts) noexcept;
  // RT thread, once per cycle.
  void record(const CycleSample& sample) noexcept;
  // RT thread, before record(): whether this cycle's sample should carry the counts. Reading the
  // thread's page faults is a system call (getrusage, about 0.3 µs here), so the executive reads
  // them every kCountsEveryCycles cycles and on the cycle that closes the warm-up, not every cycle;
  // the counts are cumulative, so nothing between two reads is lost, only reported later.
  [[nodiscard]] bool counts_due() const noexcept;
  // RT thread, once after the last cycle: the counts up to the end, so the last partial interval
  // is reported too.
  void record_final_counts(const SteadyStateCounts& counts) noexcept;

  static constexpr std::uint64_t kCountsEveryCycles = 1000;

  // Any thread.
  [[nodiscard]] RtStats snapshot() const noexcept;
  [[nodiscard]] std::uint64_t cycles() const noexcept { return cycles_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t overrun_streak() const noexcept {
    return overrun_streak_.load(std::memory_order_relaxed);
  }

 private:
  using Bins = std::array<std::atomic<std::uint64_t>, LatencyHistogram::kBins>;
  struct AtomicCounts {
    std::atomic<std::uint64_t> minor_faults{0};
    std::atomic<std::uint64_t> major_faults{0};
    std::atomic<std::uint64_t> allocations{0};
    std::atomic<std::uint64_t> deallocations{0};
    std::atomic<std::uint64_t> locks{0};
  };

  // Updates the totals and, once the warm-up is closed, the steady-state counts; `closes_warmup`:
  // the warm-up is over, so these counts become the steady state's baseline.
  void store_counts(const SteadyStateCounts& now, bool closes_warmup) noexcept;

  const std::uint64_t warmup_cycles_;
  // Writer-private baselines.
  SteadyStateCounts start_{};
  SteadyStateCounts steady_start_{};

  std::atomic<std::uint32_t> sequence_{0};
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<std::uint64_t> overruns_{0};
  std::atomic<std::uint64_t> overrun_streak_{0};
  std::atomic<std::uint64_t> max_overrun_streak_{0};
  std::atomic<std::int64_t> last_lateness_ns_{0};
  std::atomic<std::int64_t> max_lateness_ns_{0};
  std::atomic<std::int64_t> max_execution_ns_{0};
  std::atomic<bool> steady_{false};
  AtomicCounts total_;
  AtomicCounts steady_counts_;
  Bins lateness_bins_{};
  Bins execution_bins_{};
};

}  // namespace hsa::daemon
