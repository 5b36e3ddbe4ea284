#include "daemon/service/systemd_watchdog.hpp"

#include <systemd/sd-daemon.h>

#include <algorithm>

namespace hsa::daemon {

SystemdWatchdog::SystemdWatchdog(std::chrono::milliseconds interval) : interval_(interval) {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) {
    interval_ = std::min(interval_, std::chrono::milliseconds(usec / 2000));
  }
  interval_ = std::max(interval_, std::chrono::milliseconds(1));
}

SystemdWatchdog::~SystemdWatchdog() { stop(); }

void SystemdWatchdog::notify_ready(const std::string& status) {
  sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str());
}

void SystemdWatchdog::notify_status(const std::string& status) { sd_notifyf(0, "STATUS=%s", status.c_str()); }

void SystemdWatchdog::notify_stopping() { sd_notify(0, "STOPPING=1"); }

void SystemdWatchdog::start() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = false;
  }
  thread_ = std::thread([this] { run(); });
}

void SystemdWatchdog::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool SystemdWatchdog::check() {
  const std::uint64_t beats = beats_.load(std::memory_order_acquire);
  // Taken after the count: a gap recorded between the two loads is judged now, not lost.
  const std::int64_t gap = largest_gap_ns_.exchange(0, std::memory_order_relaxed);
  const bool advanced = beats != checked_beats_;
  checked_beats_ = beats;
  if (advanced && (max_gap_ns_ <= 0 || gap <= max_gap_ns_)) {
    sd_notify(0, "WATCHDOG=1");
    pings_.fetch_add(1);
    return true;
  }
  stalls_.fetch_add(1);  // no ping: systemd will restart us if this lasts WatchdogSec
  return false;
}

void SystemdWatchdog::run() {
  checked_beats_ = beats_.load(std::memory_order_relaxed);
  (void)largest_gap_ns_.exchange(0, std::memory_order_relaxed);
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, interval_, [this] { return stopping_; })) check();
}

}  // namespace hsa::daemon
