#include "drivers/sim/device_clock.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "drivers/clock.hpp"

namespace hsa::io::sim_plugin {

namespace {

std::string describe(const DeviceClockSettings& s) {
  return "step " + std::to_string(s.step_ns) + " ns, priority " + std::to_string(s.priority) + ", cpu " +
         std::to_string(s.cpu);
}

timespec to_timespec(std::int64_t ns) {
  return {static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

}  // namespace

DeviceClock& DeviceClock::instance() {
  static DeviceClock clock;
  return clock;
}

DeviceClock::~DeviceClock() { stop_thread(); }

std::string DeviceClock::attach(DeviceRig& rig, const DeviceClockSettings& settings) {
  const std::lock_guard lifecycle(lifecycle_);
  if (thread_.joinable()) {
    if (!(settings == settings_)) {
      return "timing = \"device\": the rigs of one process share one device thread, running at " +
             describe(settings_) + "; this rig asks for " + describe(settings);
    }
    const std::lock_guard lock(mutex_);
    if (std::find(rigs_.begin(), rigs_.end(), &rig) == rigs_.end()) rigs_.push_back(&rig);
    return {};
  }
  settings_ = settings;
  {
    const std::lock_guard lock(mutex_);
    rigs_.assign(1, &rig);
  }
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
  // Named, so that top -H, ps -L and a profile show which thread steps the rigs.
  (void)pthread_setname_np(thread_.native_handle(), kThreadName);
  std::string refused;
  if (settings.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(settings.cpu, &set);
    if (const int err = pthread_setaffinity_np(thread_.native_handle(), sizeof(set), &set); err != 0)
      refused = "device_cpu = " + std::to_string(settings.cpu) + ": the affinity was refused: " + std::strerror(err);
  }
  if (refused.empty() && settings.priority > 0) {
    const sched_param param{.sched_priority = settings.priority};
    if (const int err = pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &param); err != 0)
      refused = "device_priority = " + std::to_string(settings.priority) + ": SCHED_FIFO was refused: " + std::strerror(err);
  }
  if (!refused.empty()) {
    {
      const std::lock_guard lock(mutex_);
      rigs_.clear();
    }
    stop_thread();
  }
  return refused;
}

void DeviceClock::detach(DeviceRig& rig) noexcept {
  const std::lock_guard lifecycle(lifecycle_);
  bool last = false;
  {
    const std::lock_guard lock(mutex_);
    rigs_.erase(std::remove(rigs_.begin(), rigs_.end(), &rig), rigs_.end());
    last = rigs_.empty();
  }
  if (last) stop_thread();
}

std::size_t DeviceClock::attached() const {
  const std::lock_guard lock(mutex_);
  return rigs_.size();
}

void DeviceClock::stop_thread() noexcept {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void DeviceClock::run() noexcept {
  const std::int64_t step = settings_.step_ns;
  std::int64_t next = monotonic_ns();
  while (!stop_.load(std::memory_order_relaxed)) {
    next += step;
    const timespec wake = to_timespec(next);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr) == EINTR) {
    }
    // Woken late by whole steps: the device's clock ran on, so the rigs step those too.
    const std::int64_t late = monotonic_ns() - next;
    std::int64_t steps = 1 + late / step;
    if (steps > kMaxCatchUp + 1) {
      steps = kMaxCatchUp + 1;
      next = monotonic_ns();  // beyond the catch-up, the lost time is not simulated
    } else {
      next += (steps - 1) * step;
    }
    const std::lock_guard lock(mutex_);
    for (std::int64_t i = 0; i < steps; ++i) {
      for (DeviceRig* rig : rigs_) rig->step();
    }
  }
}

}  // namespace hsa::io::sim_plugin
