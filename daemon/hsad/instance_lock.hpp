// One hsad per configuration and per I/O: advisory locks that a second hsad finds taken.
//
// hsad takes, before it loads a plugin, an exclusive flock() on one file per resource it would
// drive, in a lock directory (/run/hsa by default; the systemd unit's RuntimeDirectory):
//   - the configuration file, by its canonical path;
//   - each axis on its LCM network (lcm_url and axis name): two daemons on one channel would
//     both obey its commands;
//   - each driver's endpoint, from its settings' `interface` (socketcan), `device` (a serial
//     line) or `host` and `port` (Modbus TCP) keys. GPIO lines need no file: the kernel grants a
//     line to one requester only, and the gpiod plugin names the holder when it is refused.
// The holder writes its pid into each file. A second hsad is refused with the first one's pid and
// the resource. flock() locks belong to the open file, so the kernel drops them when the holder
// exits in any way (SIGKILL included): there is no stale lock to clean up.
#pragma once

#include <string>
#include <vector>

#include "daemon/config/daemon_config.hpp"

namespace hsa::daemon {

inline constexpr const char* kDefaultLockDir = "/run/hsa";

// A resource hsad drives, and the lock file that stands for it.
struct LockedResource {
  std::string what;  // for messages: "configuration /etc/hsa/hsad.toml", "axis x on udpm://…"
  std::string file;  // the file name in the lock directory
};

// The resources of a configuration, in the order they are locked.
[[nodiscard]] std::vector<LockedResource> resources_of(const DaemonConfig& config);

class InstanceLock {
 public:
  // Creates `dir` (and its parents) if missing and locks every resource, or throws std::runtime_error
  // naming the resource, the lock file and the holder's pid. Locks taken before a refusal are
  // released.
  InstanceLock(const std::string& dir, const std::vector<LockedResource>& resources);
  ~InstanceLock();

  InstanceLock(const InstanceLock&) = delete;
  InstanceLock& operator=(const InstanceLock&) = delete;

 private:
  void release() noexcept;
  std::vector<int> fds_;
};

}  // namespace hsa::daemon
