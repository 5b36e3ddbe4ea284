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

void SystemdWatchdog::run() {
  std::uint64_t last = beats_.load(std::memory_order_relaxed);
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, interval_, [this] { return stopping_; })) {
    const std::uint64_t now = beats_.load(std::memory_order_relaxed);
    if (now != last) {
      sd_notify(0, "WATCHDOG=1");
      pings_.fetch_add(1);
    } else {
      stalls_.fetch_add(1);  // no ping: systemd will restart us if this lasts WatchdogSec
    }
    last = now;
  }
}

}  // namespace hsa::daemon
