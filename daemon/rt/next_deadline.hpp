#pragma once

#include <cstdint>

namespace hsa::daemon {

// Where the periodic loop sleeps next. The schedule stays on the grid scheduled_ns + k · period_ns
// (so it never drifts), and after an overrun the missed grid points are skipped rather than run
// back to back: catching up turns one 100 ms VM stall into 1000 late cycles, skipping
// turns it into one late cycle, as cyclictest does.
struct NextDeadline {
  std::int64_t next_ns = 0;   // the first grid point at or after now_ns, and after scheduled_ns
  std::uint64_t skipped = 0;  // grid points strictly before now_ns that are not run
};

// now_ns: when the cycle that was scheduled for scheduled_ns finished. A deadline equal to now_ns
// is not missed (sleeping until it returns at once and the cycle runs on time). The cycle overran,
// i.e. ran past its next deadline, exactly when skipped > 0. period_ns must be positive.
[[nodiscard]] NextDeadline next_deadline(std::int64_t now_ns, std::int64_t scheduled_ns,
                                         std::int64_t period_ns) noexcept;

}  // namespace hsa::daemon
