// systemd supervision of hsad (issue 4, item 12): READY=1 once the loops run, and WATCHDOG=1 from
// a normal thread only while the real-time thread's heartbeat keeps advancing. A stalled RT loop
// therefore stops the pings and systemd restarts the service after WatchdogSec.
//
// The RT thread's only part is to bump an atomic counter every cycle (heartbeat()); everything
// that makes a system call happens here, off the RT thread. Outside systemd (no NOTIFY_SOCKET)
// sd_notify is a no-op and so is all of this.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace hsa::daemon {

class SystemdWatchdog {
 public:
  // `interval` is how often the heartbeat is checked and WATCHDOG=1 sent; systemd's own
  // WATCHDOG_USEC, when set, caps it at half the watchdog period.
  explicit SystemdWatchdog(std::chrono::milliseconds interval = std::chrono::milliseconds(200));
  ~SystemdWatchdog();
  SystemdWatchdog(const SystemdWatchdog&) = delete;
  SystemdWatchdog& operator=(const SystemdWatchdog&) = delete;

  // Called by the RT thread once per cycle: one relaxed atomic increment.
  void heartbeat() noexcept { beats_.fetch_add(1, std::memory_order_relaxed); }

  void notify_ready(const std::string& status);
  void notify_status(const std::string& status);
  void notify_stopping();

  void start();  // the checking thread
  void stop();

  [[nodiscard]] std::uint64_t pings_sent() const { return pings_.load(); }
  [[nodiscard]] std::uint64_t stalls_seen() const { return stalls_.load(); }
  [[nodiscard]] std::chrono::milliseconds interval() const { return interval_; }

 private:
  void run();

  std::chrono::milliseconds interval_;
  std::atomic<std::uint64_t> beats_{0};
  std::atomic<std::uint64_t> pings_{0};
  std::atomic<std::uint64_t> stalls_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hsa::daemon
