#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace hsa::daemon {

// What the real-time executive asks of the kernel, and its period. The daemon
// fills it from the TOML configuration; the defaults are the 100 µs base tick at SCHED_FIFO 80.
struct RtConfig {
  int priority = 80;                          // SCHED_FIFO priority, 1..99
  int cpu = -1;                               // CPU to pin the RT thread to; -1 leaves it free
  bool require_realtime = false;              // refuse to start when SCHED_FIFO/mlockall/affinity is refused
  std::chrono::nanoseconds period{100'000};   // base tick
  std::size_t stack_prefault_bytes = 256 * 1024;  // touched on the RT thread before the first cycle
  // Cycles after which the steady state begins: lazy first-use work (PLT binding, first touch of
  // code pages without mlockall, the task's own first cycle) is allowed to fault before it, and the
  // steady-state allocation, lock and page-fault counts start from here. 1000 cycles = 0.1 s.
  std::uint64_t warmup_cycles = 1000;
};

}  // namespace hsa::daemon
