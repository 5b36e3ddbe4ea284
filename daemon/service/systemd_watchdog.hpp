// systemd supervision of hsad: READY=1 once the loops run, and WATCHDOG=1 from a normal thread
// only while control is real: in the interval since the last check the RT thread completed at
// least one cycle, and no two of its heartbeats (nor the first one and the last heartbeat of the
// interval before) were further apart than max_gap (the axes' blind-time bound). A stalled RT
// loop, or one that only limps (a 50 ms stall between otherwise regular cycles), therefore misses
// that interval's ping, and systemd restarts the service after WatchdogSec of missed pings.
//
// The RT thread's part is heartbeat(now): a relaxed increment and a lock-free running maximum of
// the gap between heartbeats; everything that makes a system call happens here, off the RT
// thread. Outside systemd (no NOTIFY_SOCKET)
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

  // The largest gap between heartbeats an interval may contain and still be pinged. Set before
  // start(); zero (the default) judges only that the heartbeat advanced.
  void set_max_gap(std::chrono::nanoseconds gap) { max_gap_ns_ = gap.count(); }

  // Called by the RT thread once per cycle with the cycle's time (any monotonic ns clock).
  void heartbeat(std::int64_t now_ns) noexcept {
    if (have_beat_) {
      const std::int64_t gap = now_ns - last_beat_ns_;
      std::int64_t seen = largest_gap_ns_.load(std::memory_order_relaxed);
      while (gap > seen &&
             !largest_gap_ns_.compare_exchange_weak(seen, gap, std::memory_order_relaxed)) {
      }
    }
    have_beat_ = true;
    last_beat_ns_ = now_ns;
    beats_.fetch_add(1, std::memory_order_release);
  }

  // One check, as the thread makes every interval: pings (and returns true) when heartbeats came
  // since the last check and the largest gap among them is within max_gap. Public so that a test
  // can drive the checks in a known order against a scripted heartbeat.
  bool check();

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
  std::atomic<std::int64_t> largest_gap_ns_{0};  // since the last check
  std::int64_t max_gap_ns_ = 0;
  // RT thread only.
  bool have_beat_ = false;
  std::int64_t last_beat_ns_ = 0;
  // Checking thread only.
  std::uint64_t checked_beats_ = 0;
  std::atomic<std::uint64_t> pings_{0};
  std::atomic<std::uint64_t> stalls_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hsa::daemon
