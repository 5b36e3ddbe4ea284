#pragma once

#include <cstdint>

#include "daemon/rt/latency_histogram.hpp"

namespace hsa::daemon {

// One consistent view of the RT loop's timing and steady-state counters,
// taken by RtExecutive::snapshot() from any thread. Lateness is woke − scheduled; execution is the
// time from wake-up to the end of the cycle's bookkeeping; an overrun is a cycle that ended after
// its next deadline, whose missed periods were then skipped.
//
// "steady" counters start after RtConfig::warmup_cycles cycles and stay 0 until then; the others
// count from the first cycle. Allocations and locks are those made with the RT-cycle flag set, and
// are 0 when hsa_rt_counters is not linked (counters_linked says which). Page faults are the RT
// thread's own (getrusage RUSAGE_THREAD), read every RtStatsRecorder::kCountsEveryCycles cycles and
// after the last one: cumulative, so a fault is never missed, only reported up to 0.1 s later.
struct RtStats {
  std::uint64_t cycles = 0;
  std::uint64_t skipped_periods = 0;
  std::uint64_t overruns = 0;
  std::uint64_t overrun_streak = 0;      // consecutive overruns ending with the latest cycle
  std::uint64_t max_overrun_streak = 0;
  std::int64_t last_lateness_ns = 0;
  std::int64_t max_lateness_ns = 0;
  std::int64_t max_execution_ns = 0;
  Percentiles lateness;                  // from the histograms, see histogram_percentile_ns()
  Percentiles execution;
  LatencyHistogram::Counts lateness_histogram{};
  LatencyHistogram::Counts execution_histogram{};

  bool steady = false;  // warm-up done
  bool counters_linked = false;
  std::uint64_t minor_faults = 0;
  std::uint64_t major_faults = 0;
  std::uint64_t allocations = 0;
  std::uint64_t deallocations = 0;
  std::uint64_t locks = 0;
  std::uint64_t steady_minor_faults = 0;
  std::uint64_t steady_major_faults = 0;
  std::uint64_t steady_allocations = 0;
  std::uint64_t steady_deallocations = 0;
  std::uint64_t steady_locks = 0;
};

}  // namespace hsa::daemon
