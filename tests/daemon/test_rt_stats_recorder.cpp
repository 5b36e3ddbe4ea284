#include "daemon/rt/rt_stats_recorder.hpp"

#include <atomic>
#include <numeric>
#include <thread>

#include <gtest/gtest.h>

namespace hsa::daemon {
namespace {

std::uint64_t sum(const LatencyHistogram::Counts& counts) {
  return std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
}

CycleSample on_time(std::int64_t lateness_ns, std::int64_t execution_ns, SteadyStateCounts counts = {}) {
  return CycleSample{lateness_ns, execution_ns, 0, counts};
}

TEST(RtStatsRecorder, CountsEveryCycleInBothHistogramsAndKeepsTheMaxima) {
  RtStatsRecorder recorder(0);
  recorder.begin({});
  recorder.record(on_time(3'000, 20'000));
  recorder.record(on_time(250'000, 15'000));
  recorder.record(on_time(7'500, 31'000));
  const RtStats s = recorder.snapshot();
  EXPECT_EQ(s.cycles, 3U);
  EXPECT_EQ(sum(s.lateness_histogram), 3U);
  EXPECT_EQ(sum(s.execution_histogram), 3U);
  EXPECT_EQ(s.lateness_histogram[LatencyHistogram::bin_of(250'000)], 1U);
  EXPECT_EQ(s.max_lateness_ns, 250'000);
  EXPECT_EQ(s.max_execution_ns, 31'000);
  EXPECT_EQ(s.last_lateness_ns, 7'500);
  EXPECT_EQ(s.lateness.p50_ns, 7'000);
  EXPECT_EQ(s.overruns, 0U);
}

TEST(RtStatsRecorder, OverrunStreakCountsConsecutiveOverrunsAndResets) {
  RtStatsRecorder recorder(0);
  recorder.begin({});
  const CycleSample overrun{1'000, 150'000, 1, {}};
  recorder.record(overrun);
  recorder.record(CycleSample{1'000, 350'000, 3, {}});
  EXPECT_EQ(recorder.overrun_streak(), 2U);
  recorder.record(on_time(1'000, 10'000));
  EXPECT_EQ(recorder.overrun_streak(), 0U);
  recorder.record(overrun);
  const RtStats s = recorder.snapshot();
  EXPECT_EQ(s.overruns, 3U);
  EXPECT_EQ(s.skipped_periods, 5U);
  EXPECT_EQ(s.overrun_streak, 1U);
  EXPECT_EQ(s.max_overrun_streak, 2U);
}

TEST(RtStatsRecorder, SteadyStateCountsStartAfterTheWarmUp) {
  RtStatsRecorder recorder(2);
  recorder.begin({10, 1, 100, 100, 50});
  recorder.record(on_time(0, 0, {15, 1, 103, 102, 50}));  // warm-up: faults and allocations allowed
  EXPECT_FALSE(recorder.snapshot().steady);
  recorder.record(on_time(0, 0, {17, 2, 104, 104, 51}));  // closes the warm-up
  RtStats s = recorder.snapshot();
  EXPECT_TRUE(s.steady);
  EXPECT_EQ(s.steady_minor_faults, 0U);
  EXPECT_EQ(s.minor_faults, 7U);
  EXPECT_EQ(s.major_faults, 1U);
  EXPECT_EQ(s.allocations, 4U);
  EXPECT_EQ(s.deallocations, 4U);
  EXPECT_EQ(s.locks, 1U);

  recorder.record(on_time(0, 0, {17, 2, 104, 104, 51}));
  s = recorder.snapshot();
  EXPECT_EQ(s.steady_minor_faults, 0U);
  EXPECT_EQ(s.steady_allocations, 0U);
  EXPECT_EQ(s.steady_locks, 0U);

  recorder.record(on_time(0, 0, {20, 2, 106, 105, 54}));
  s = recorder.snapshot();
  EXPECT_EQ(s.steady_minor_faults, 3U);
  EXPECT_EQ(s.steady_major_faults, 0U);
  EXPECT_EQ(s.steady_allocations, 2U);
  EXPECT_EQ(s.steady_deallocations, 1U);
  EXPECT_EQ(s.steady_locks, 3U);
  EXPECT_EQ(s.minor_faults, 10U);
}

TEST(RtStatsRecorder, ZeroWarmUpIsSteadyFromTheStart) {
  RtStatsRecorder recorder(0);
  recorder.begin({5, 0, 0, 0, 0});
  EXPECT_TRUE(recorder.snapshot().steady);
  recorder.record(on_time(0, 0, {6, 0, 0, 0, 0}));
  EXPECT_EQ(recorder.snapshot().steady_minor_faults, 1U);
}

// The executive reads the counts (a system call) only when they are due: on the cycle that closes
// the warm-up and every kCountsEveryCycles-th cycle. They are cumulative, so a fault between two
// reads shows at the next one, and the final read after the last cycle reports the rest.
TEST(RtStatsRecorder, CountsAreDueAtTheWarmUpEveryNthCycleAndAtTheEnd) {
  constexpr std::uint64_t kWarmup = 3;
  RtStatsRecorder recorder(kWarmup);
  recorder.begin({0, 0, 0, 0, 0});
  std::uint64_t due = 0;
  std::uint64_t faults = 0;  // the thread's cumulative page faults, one more every 100 cycles
  const std::uint64_t cycles = 2 * RtStatsRecorder::kCountsEveryCycles + 50;
  for (std::uint64_t c = 1; c <= cycles; ++c) {
    if (c % 100 == 0) ++faults;
    const bool read = recorder.counts_due();
    EXPECT_EQ(read, c == kWarmup || c % RtStatsRecorder::kCountsEveryCycles == 0) << "cycle " << c;
    due += read ? 1 : 0;
    CycleSample sample = on_time(0, 0);
    if (read) sample.counts = SteadyStateCounts{faults, 0, 0, 0, 0};
    else sample.counts.reset();
    recorder.record(sample);
  }
  EXPECT_EQ(due, 3u);
  RtStats s = recorder.snapshot();
  EXPECT_TRUE(s.steady);
  EXPECT_EQ(s.steady_minor_faults, 20u);  // read at cycle 2000: the faults of cycles 100..2000
  recorder.record_final_counts({faults, 0, 0, 0, 0});
  s = recorder.snapshot();
  EXPECT_EQ(s.steady_minor_faults, faults);  // the last 50 cycles too (none faulted)
  EXPECT_EQ(s.minor_faults, faults);
  EXPECT_EQ(s.cycles, cycles);
}

// A run that ends inside the warm-up stays unsteady: the final read is not a cycle.
TEST(RtStatsRecorder, TheFinalReadDoesNotCloseTheWarmUp) {
  RtStatsRecorder recorder(10);
  recorder.begin({0, 0, 0, 0, 0});
  recorder.record(on_time(0, 0));
  recorder.record_final_counts({4, 0, 0, 0, 0});
  const RtStats s = recorder.snapshot();
  EXPECT_FALSE(s.steady);
  EXPECT_EQ(s.minor_faults, 4u);
  EXPECT_EQ(s.steady_minor_faults, 0u);
}

TEST(RtStatsRecorder, ConcurrentSnapshotsAreConsistent) {
  // The seqlock's promise: a reader never sees a half-written cycle, so the histogram always sums to
  // the cycle count, however the two threads interleave.
  RtStatsRecorder recorder(0);
  recorder.begin({});
  constexpr std::uint64_t kCycles = 200'000;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> snapshots_taken{0};
  std::thread writer([&] {
    for (std::uint64_t i = 0; i < kCycles; ++i) {
      // Every 1000 records, wait for the reader to take another snapshot: on a loaded machine the
      // writer could otherwise finish before the reader ever runs, and nothing would overlap.
      if (i % 1000 == 0)
        while (snapshots_taken.load() <= i / 1000) std::this_thread::yield();
      recorder.record(CycleSample{static_cast<std::int64_t>(i % 3000) * 1'000, 5'000, i % 7 == 0 ? 1U : 0U, {}});
    }
    done.store(true);
  });
  std::uint64_t snapshots = 0;
  std::uint64_t inconsistent = 0;
  while (!done.load()) {
    const RtStats s = recorder.snapshot();
    inconsistent += sum(s.lateness_histogram) != s.cycles || sum(s.execution_histogram) != s.cycles;
    ++snapshots;
    snapshots_taken.store(snapshots);
  }
  writer.join();
  EXPECT_GE(snapshots, kCycles / 1000);
  EXPECT_EQ(inconsistent, 0U);
  const RtStats s = recorder.snapshot();
  EXPECT_EQ(s.cycles, kCycles);
  EXPECT_EQ(s.overruns, (kCycles + 6) / 7);
}

}  // namespace
}  // namespace hsa::daemon
