// One hsad per configuration and per I/O: advisory locks that a second hsad finds taken.
//
// hsad takes, before it opens a device, an exclusive flock() on one file per resource it would
// drive, in a lock directory (/run/hsa by default; the systemd unit's RuntimeDirectory):
//   - the configuration file, by its canonical path;
//   - each axis on its LCM network: the multicast group and port of lcm_url (not its text: `?ttl=0`
//     and `?ttl=1` on one group and port are one network) and the axis name, since two daemons on
//     one channel would both obey its commands;
//   - each device a driver opens, as its plugin states it from its settings with the plugin's own
//     defaults applied (Driver::plan: "modbus-tcp:10.0.0.5:502", "serial:/dev/ttyUSB0",
//     "can:can0", "gpiochip:gpiochip0"), so that two spellings of one device are one lock.
// The holder writes its pid into each file. A second hsad is refused with the first one's pid and
// the resource. flock() locks belong to the open file, so the kernel drops them when the holder
// exits in any way (SIGKILL included): there is no stale lock to clean up.
#pragma once

#include <string>
#include <vector>

#include "daemon/config/daemon_config.hpp"
#include "daemon/hsad/driver_set.hpp"

namespace hsa::daemon {

inline constexpr const char* kDefaultLockDir = "/run/hsa";

// A resource hsad drives, and the lock file that stands for it.
struct LockedResource {
  std::string what;  // for messages: "configuration /etc/hsa/hsad.toml", "axis x on udpm://…"
  std::string file;  // the file name in the lock directory
};

// The resources of a configuration whose drivers have the plans `drivers` (plan_drivers), in the
// order they are locked. Throws std::invalid_argument for an LCM URL without a usable address.
[[nodiscard]] std::vector<LockedResource> resources_of(const DaemonConfig& config,
                                                       const std::vector<PlannedDriver>& drivers);

// `hsad --check-config`: the refusal InstanceLock would give now, or "" when no resource is held.
// Takes no lock and creates no file (a missing lock file is a free resource).
[[nodiscard]] std::string held_resource(const std::string& dir, const std::vector<LockedResource>& resources);

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
