#pragma once

namespace hsa::daemon {

// "This thread is inside an RT cycle": set by the executive from wake-up to the next sleep, read by
// the test-build counters (daemon/rt/alloc_counter.cpp, lock_counter.cpp) to count only what the
// cycle itself does. A header-only inline variable, so hsa_daemon_rt (which sets it) and
// hsa_rt_counters (which reads it) share one definition without either linking the other; constinit
// so reading it from operator new or pthread_mutex_lock needs no TLS initialization guard.
inline constinit thread_local bool t_in_rt_cycle = false;

[[nodiscard]] inline bool in_rt_cycle() noexcept { return t_in_rt_cycle; }

// Marks the current thread as in an RT cycle for its lifetime (and restores what was there).
class RtCycleScope {
 public:
  RtCycleScope() noexcept : previous_(t_in_rt_cycle) { t_in_rt_cycle = true; }
  ~RtCycleScope() { t_in_rt_cycle = previous_; }
  RtCycleScope(const RtCycleScope&) = delete;
  RtCycleScope& operator=(const RtCycleScope&) = delete;

 private:
  bool previous_;
};

}  // namespace hsa::daemon
