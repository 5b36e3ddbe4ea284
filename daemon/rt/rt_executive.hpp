#pragma once

#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "daemon/rt/cycle_task.hpp"
#include "daemon/rt/realtime_grant.hpp"
#include "daemon/rt/rt_config.hpp"
#include "daemon/rt/rt_platform.hpp"
#include "daemon/rt/rt_stats.hpp"
#include "daemon/rt/rt_stats_recorder.hpp"

namespace hsa::daemon {

// The real-time executive: one thread that calls CycleTask::cycle() once per
// period.
//
// start() creates the thread (only it: when the daemon's other threads start is the daemon's job).
// The thread, before its first cycle, pins itself to RtConfig::cpu (if ≥ 0), calls
// mlockall(MCL_CURRENT|MCL_FUTURE), switches itself to SCHED_FIFO at RtConfig::priority and writes
// RtConfig::stack_prefault_bytes of its own stack so those pages exist. What was refused is
// reported back to start(): with require_realtime it throws and no cycle runs; otherwise it warns
// once through the warning handler and runs anyway.
//
// The loop sleeps with clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME) on a fixed grid. Each cycle
// measures its lateness (woke − scheduled) and execution time into RtStatsRecorder (histograms,
// maxima, overruns and the overrun streak) and, after an overrun, skips the periods it missed
// (next_deadline()) instead of bursting through them. From wake-up to the next sleep the
// RT-cycle flag is set (rt_cycle_flag.hpp), so a test build with hsa_rt_counters counts every
// allocation and lock made in the cycle; the thread's page faults are read with getrusage at the end
// of every RtStatsRecorder::kCountsEveryCycles-th cycle (a system call of about 0.3 µs, which every
// cycle would pay otherwise), of the cycle that closes the warm-up, and once after the last cycle.
// The cycle itself allocates nothing, locks nothing and makes no system call besides the sleep
// (clock_gettime is vDSO) but that periodic getrusage.
//
// Threading: start(), stop() and the destructor from one controlling thread; request_stop() from
// anywhere, including a signal handler; snapshot(), cycles() and overrun_streak() from any thread,
// without locks.
class RtExecutive {
 public:
  using WarningHandler = std::function<void(const std::string&)>;

  // Throws std::invalid_argument for a non-positive period or a priority outside 1..99.
  RtExecutive(RtConfig config, CycleTask& task, RtPlatform& platform = linux_rt_platform());
  ~RtExecutive();
  RtExecutive(const RtExecutive&) = delete;
  RtExecutive& operator=(const RtExecutive&) = delete;

  // Called at most once, from start(), when something was refused and the loop runs anyway. The
  // default writes the message as one line to stderr (journald picks it up under systemd).
  void set_warning_handler(WarningHandler handler);

  // Creates the RT thread and returns once it has run its set-up. Throws std::runtime_error naming
  // each refusal and its errno text when require_realtime is set and something was refused,
  // std::system_error if the thread cannot be created, std::logic_error on a second call.
  RealtimeGrant start();

  // Async-signal-safe: sets an atomic flag; the loop exits at its next wake-up (≤ one period).
  void request_stop() noexcept;
  // request_stop() and join. Idempotent.
  void stop();

  [[nodiscard]] bool running() const noexcept { return running_; }
  [[nodiscard]] const RtConfig& config() const noexcept { return config_; }
  [[nodiscard]] const RealtimeGrant& grant() const noexcept { return grant_; }

  [[nodiscard]] RtStats snapshot() const noexcept { return recorder_.snapshot(); }
  // Cycles run so far: the heartbeat the sd_notify watchdog thread checks.
  [[nodiscard]] std::uint64_t cycles() const noexcept { return recorder_.cycles(); }
  [[nodiscard]] std::uint64_t overrun_streak() const noexcept { return recorder_.overrun_streak(); }

 private:
  enum SetupState : int { kPending = 0, kReady = 1, kRefused = 2 };

  static void* thread_main(void* self) noexcept;
  void run() noexcept;
  void loop() noexcept;

  const RtConfig config_;
  CycleTask& task_;
  RtPlatform& platform_;
  WarningHandler warn_;
  RealtimeGrant grant_;

  pthread_t thread_{};
  bool started_ = false;
  bool running_ = false;
  std::atomic<bool> stop_requested_{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "request_stop() must be async-signal-safe");

  // Set-up results, written by the RT thread before setup_state_ leaves kPending: errno values, or
  // 0 for granted (and for affinity, also when no CPU was asked for).
  int affinity_errno_ = 0;
  int mlock_errno_ = 0;
  int fifo_errno_ = 0;
  std::atomic<int> setup_state_{kPending};

  RtStatsRecorder recorder_;
};

}  // namespace hsa::daemon
