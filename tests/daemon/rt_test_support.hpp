#pragma once

// Shared by the daemon/rt tests: a task that records its timings into preallocated storage and
// stops the executive after a given number of cycles, and a runner that waits for it with a
// generous timeout (the tests never assert timing).

#include <pthread.h>
#include <sched.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "daemon/rt/cycle_task.hpp"
#include "daemon/rt/rt_cycle_flag.hpp"
#include "daemon/rt/rt_executive.hpp"

namespace hsa::daemon::testing {

class RecordingTask : public CycleTask {
 public:
  static constexpr std::size_t kCapacity = 4096;

  explicit RecordingTask(std::uint64_t cycles_to_run) : cycles_to_run_(cycles_to_run) {}

  void attach(RtExecutive& executive) { executive_ = &executive; }

  void cycle(const CycleTiming& timing) noexcept override {
    if (count_ < kCapacity) {
      timings_[count_] = timing;
      flag_seen_[count_] = in_rt_cycle();
      cpus_[count_] = sched_getcpu();
      int policy = 0;
      sched_param param{};
      pthread_getschedparam(pthread_self(), &policy, &param);
      policies_[count_] = policy;
      priorities_[count_] = param.sched_priority;
    }
    work(count_);
    ++count_;
    if (count_ == cycles_to_run_) {
      executive_->request_stop();
      finished_.store(true, std::memory_order_release);
    }
  }

  // What the task does besides recording, in cycle `index` (0-based).
  virtual void work(std::uint64_t /*index*/) noexcept {}

  [[nodiscard]] bool finished() const { return finished_.load(std::memory_order_acquire); }
  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] const CycleTiming& timing(std::size_t i) const { return timings_.at(i); }
  [[nodiscard]] bool flag_seen(std::size_t i) const { return flag_seen_.at(i); }
  [[nodiscard]] int cpu(std::size_t i) const { return cpus_.at(i); }
  [[nodiscard]] int policy(std::size_t i) const { return policies_.at(i); }
  [[nodiscard]] int priority(std::size_t i) const { return priorities_.at(i); }

 private:
  const std::uint64_t cycles_to_run_;
  RtExecutive* executive_ = nullptr;
  std::uint64_t count_ = 0;
  std::atomic<bool> finished_{false};
  std::array<CycleTiming, kCapacity> timings_{};
  std::array<bool, kCapacity> flag_seen_{};
  std::array<int, kCapacity> cpus_{};
  std::array<int, kCapacity> policies_{};
  std::array<int, kCapacity> priorities_{};
};

// Starts the executive, waits (up to 20 s) for the task to have run its cycles, stops, and returns
// the grant. Returns with finished() false on timeout; callers assert on it.
inline RealtimeGrant run_to_completion(RtExecutive& executive, RecordingTask& task) {
  task.attach(executive);
  RealtimeGrant grant = executive.start();
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!task.finished() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  executive.stop();
  return grant;
}

}  // namespace hsa::daemon::testing
