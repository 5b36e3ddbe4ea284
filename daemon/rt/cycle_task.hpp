#pragma once

#include <cstdint>

namespace hsa::daemon {

// What one cycle knows about its own timing. All times are CLOCK_MONOTONIC in ns.
//
// tick is the index of the period this cycle was scheduled for, counted from the first cycle (0):
// scheduled_ns = first_scheduled_ns + tick · period_ns. After an overrun the executive skips the
// periods it missed instead of running them back to back, so tick then advances by 1 + skipped.
// A task that runs something every Nth tick should therefore test whether tick / N changed since
// its last cycle, not whether tick % N == 0, or a skip can silently drop the slower loop's turn.
struct CycleTiming {
  std::int64_t scheduled_ns = 0;  // the deadline this cycle slept until
  std::int64_t woke_ns = 0;       // when the thread actually woke; woke − scheduled is the lateness
  std::int64_t period_ns = 0;
  std::uint64_t tick = 0;
  std::uint64_t skipped = 0;         // periods skipped just before this cycle (0 when on time)
  std::uint64_t overrun_streak = 0;  // consecutive overruns up to and including the previous cycle
};

// The daemon's work, called once per period on the RT thread. noexcept because an exception has
// nowhere safe to go on the RT thread; it must not allocate, lock or block (docs/architecture.md, real-time rules).
class CycleTask {
 public:
  virtual ~CycleTask() = default;
  virtual void cycle(const CycleTiming& timing) noexcept = 0;
};

}  // namespace hsa::daemon
