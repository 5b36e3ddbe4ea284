#include "daemon/rt/rt_stats_recorder.hpp"

#include <sched.h>


#include "daemon/rt/rt_counters.hpp"

namespace hsa::daemon {
namespace {

constexpr auto kRelaxed = std::memory_order_relaxed;
// The seqlock's ordering comes from release stores of the data (none can move before the odd
// sequence number) and acquire loads of it (the final sequence load cannot move before them), not
// from fences: on x86 both are plain moves, and ThreadSanitizer understands them.
constexpr auto kRelease = std::memory_order_release;
constexpr auto kAcquire = std::memory_order_acquire;

// Single writer: a load and a store instead of a read-modify-write, which would be a locked
// instruction for nothing.
template <typename T>
void add(std::atomic<T>& a, T delta) noexcept {
  a.store(a.load(kRelaxed) + delta, kRelease);
}

template <typename T>
void raise_to(std::atomic<T>& a, T value) noexcept {
  if (value > a.load(kRelaxed)) {
    a.store(value, kRelease);
  }
}

void store_delta(std::atomic<std::uint64_t>& a, std::uint64_t now, std::uint64_t base) noexcept {
  a.store(now >= base ? now - base : 0, kRelease);
}

}  // namespace

RtStatsRecorder::RtStatsRecorder(std::uint64_t warmup_cycles) noexcept : warmup_cycles_(warmup_cycles) {
  // Write every bin once so the pages are really there (not the shared zero page) before the RT
  // thread starts, whether or not mlockall is granted.
  for (auto& bin : lateness_bins_) {
    bin.store(0, kRelaxed);
  }
  for (auto& bin : execution_bins_) {
    bin.store(0, kRelaxed);
  }
}

void RtStatsRecorder::begin(const SteadyStateCounts& counts) noexcept {
  start_ = counts;
  if (warmup_cycles_ == 0) {
    steady_start_ = counts;
    steady_.store(true, kRelease);
  }
}

void RtStatsRecorder::record(const CycleSample& sample) noexcept {
  const std::uint32_t seq = sequence_.load(kRelaxed);
  sequence_.store(seq + 1, kRelaxed);

  const std::uint64_t cycles = cycles_.load(kRelaxed) + 1;
  cycles_.store(cycles, kRelease);
  add(lateness_bins_[LatencyHistogram::bin_of(sample.lateness_ns)], std::uint64_t{1});
  add(execution_bins_[LatencyHistogram::bin_of(sample.execution_ns)], std::uint64_t{1});
  last_lateness_ns_.store(sample.lateness_ns, kRelease);
  raise_to(max_lateness_ns_, sample.lateness_ns);
  raise_to(max_execution_ns_, sample.execution_ns);
  if (sample.skipped > 0) {
    add(skipped_, sample.skipped);
    add(overruns_, std::uint64_t{1});
    add(overrun_streak_, std::uint64_t{1});
    raise_to(max_overrun_streak_, overrun_streak_.load(kRelaxed));
  } else {
    overrun_streak_.store(0, kRelease);
  }

  if (sample.counts) store_counts(*sample.counts, cycles >= warmup_cycles_);

  sequence_.store(seq + 2, std::memory_order_release);
}

bool RtStatsRecorder::counts_due() const noexcept {
  const std::uint64_t next = cycles_.load(kRelaxed) + 1;
  return (!steady_.load(kRelaxed) && next >= warmup_cycles_) || next % kCountsEveryCycles == 0;
}

void RtStatsRecorder::record_final_counts(const SteadyStateCounts& counts) noexcept {
  const std::uint32_t seq = sequence_.load(kRelaxed);
  sequence_.store(seq + 1, kRelaxed);
  // Not a cycle: the warm-up does not close here, so a run shorter than it stays unsteady.
  store_counts(counts, false);
  sequence_.store(seq + 2, std::memory_order_release);
}

void RtStatsRecorder::store_counts(const SteadyStateCounts& now, bool closes_warmup) noexcept {
  store_delta(total_.minor_faults, now.minor_faults, start_.minor_faults);
  store_delta(total_.major_faults, now.major_faults, start_.major_faults);
  store_delta(total_.allocations, now.allocations, start_.allocations);
  store_delta(total_.deallocations, now.deallocations, start_.deallocations);
  store_delta(total_.locks, now.locks, start_.locks);
  if (!steady_.load(kRelaxed) && closes_warmup) {
    // This cycle closes the warm-up: what happens from the next one on is steady state.
    steady_start_ = now;
    steady_.store(true, kRelease);
  } else if (steady_.load(kRelaxed)) {
    store_delta(steady_counts_.minor_faults, now.minor_faults, steady_start_.minor_faults);
    store_delta(steady_counts_.major_faults, now.major_faults, steady_start_.major_faults);
    store_delta(steady_counts_.allocations, now.allocations, steady_start_.allocations);
    store_delta(steady_counts_.deallocations, now.deallocations, steady_start_.deallocations);
    store_delta(steady_counts_.locks, now.locks, steady_start_.locks);
  }
}

RtStats RtStatsRecorder::snapshot() const noexcept {
  RtStats s;
  for (unsigned attempt = 0;; ++attempt) {
    const std::uint32_t before = sequence_.load(std::memory_order_acquire);
    if ((before & 1U) == 0) {
      s.cycles = cycles_.load(kAcquire);
      s.skipped_periods = skipped_.load(kAcquire);
      s.overruns = overruns_.load(kAcquire);
      s.overrun_streak = overrun_streak_.load(kAcquire);
      s.max_overrun_streak = max_overrun_streak_.load(kAcquire);
      s.last_lateness_ns = last_lateness_ns_.load(kAcquire);
      s.max_lateness_ns = max_lateness_ns_.load(kAcquire);
      s.max_execution_ns = max_execution_ns_.load(kAcquire);
      for (std::size_t b = 0; b < LatencyHistogram::kBins; ++b) {
        s.lateness_histogram[b] = lateness_bins_[b].load(kAcquire);
        s.execution_histogram[b] = execution_bins_[b].load(kAcquire);
      }
      s.steady = steady_.load(kAcquire);
      s.minor_faults = total_.minor_faults.load(kAcquire);
      s.major_faults = total_.major_faults.load(kAcquire);
      s.allocations = total_.allocations.load(kAcquire);
      s.deallocations = total_.deallocations.load(kAcquire);
      s.locks = total_.locks.load(kAcquire);
      s.steady_minor_faults = steady_counts_.minor_faults.load(kAcquire);
      s.steady_major_faults = steady_counts_.major_faults.load(kAcquire);
      s.steady_allocations = steady_counts_.allocations.load(kAcquire);
      s.steady_deallocations = steady_counts_.deallocations.load(kAcquire);
      s.steady_locks = steady_counts_.locks.load(kAcquire);
      if (sequence_.load(kRelaxed) == before) {
        break;
      }
    }
    // Without SCHED_FIFO the writer can be preempted mid-update on this reader's CPU: let it run.
    if (attempt % 16 == 15) {
      sched_yield();
    }
  }
  s.lateness = histogram_percentiles(s.lateness_histogram);
  s.execution = histogram_percentiles(s.execution_histogram);
  s.counters_linked = rt_counters_linked();
  return s;
}

}  // namespace hsa::daemon
