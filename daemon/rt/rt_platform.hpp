#pragma once

namespace hsa::daemon {

// The three kernel requests the executive makes on its RT thread, behind an interface so tests can
// simulate a refusal even when they run as root. Each returns 0 or the errno value of the refusal.
class RtPlatform {
 public:
  virtual ~RtPlatform() = default;
  virtual int lock_memory() noexcept = 0;                        // mlockall(MCL_CURRENT|MCL_FUTURE)
  virtual int set_fifo_priority(int priority) noexcept = 0;      // SCHED_FIFO for the calling thread
  virtual int pin_to_cpu(int cpu) noexcept = 0;                  // affinity of the calling thread
};

// The real thing.
[[nodiscard]] RtPlatform& linux_rt_platform() noexcept;

}  // namespace hsa::daemon
