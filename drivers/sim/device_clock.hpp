// The sim plugin's device thread: it steps every rig configured with `timing = "device"` on its
// own clock, every step_s on CLOCK_MONOTONIC, as the rig's own electronics would, while the RT
// thread reads and writes them through their mailboxes (device_rig.hpp).
//
// One thread for every device-timed rig of the process, not one per rig: 64 axes would otherwise
// be 64 threads waking 10 000 times a second each. So they share its settings: the first rig
// attached starts the thread with its step, priority and CPU, a rig asking for others is refused,
// and the last rig detached stops it.
//
// The thread holds a mutex while it steps the rigs; attach() and detach() take it from the
// daemon's configuring threads (never the RT thread), so a rig is never stepped while it is added
// or removed. They take a second one between them, held while the thread starts or is joined, so
// that the thread is never joined while it waits for the first. Woken late by whole steps, the thread steps the rigs that many more times (at most
// kMaxCatchUp; beyond, the lost time is not simulated), so the rigs keep the wall clock's pace.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/sim/device_rig.hpp"

namespace hsa::io::sim_plugin {

struct DeviceClockSettings {
  std::int64_t step_ns = 100'000;
  int priority = 0;  // SCHED_FIFO priority 1..99; 0: the scheduling of the thread that attaches
  int cpu = -1;      // pinned to this CPU; -1: the affinity of the thread that attaches
  bool operator==(const DeviceClockSettings&) const = default;
};

class DeviceClock {
 public:
  static constexpr std::int64_t kMaxCatchUp = 100;
  static constexpr const char* kThreadName = "hsa-sim-device";  // its comm (15 characters at most)

  static DeviceClock& instance();

  // Adds `rig` to the rigs the thread steps, starting the thread if it is the first. Returns an
  // empty string, or why the rig was refused (other settings than the running thread's, or the
  // priority or CPU refused by the system); a refused rig is not attached.
  std::string attach(DeviceRig& rig, const DeviceClockSettings& settings);
  // Removes `rig` (a rig not attached is ignored); the last one stops the thread. After it
  // returns the thread no longer touches `rig`.
  void detach(DeviceRig& rig) noexcept;

  [[nodiscard]] std::size_t attached() const;

  ~DeviceClock();

 private:
  DeviceClock() = default;
  void run() noexcept;
  void stop_thread() noexcept;

  std::mutex lifecycle_;     // attach() and detach() one at a time, the thread's start and stop too
  mutable std::mutex mutex_;  // the rigs: held by the thread while it steps them
  std::vector<DeviceRig*> rigs_;
  DeviceClockSettings settings_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace hsa::io::sim_plugin
