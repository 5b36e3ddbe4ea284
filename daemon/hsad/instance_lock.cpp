#include "daemon/hsad/instance_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "daemon/lcm_bridge/lcm_url.hpp"

namespace hsa::daemon {
namespace {

// A file name that stands for `key`: every byte outside [A-Za-z0-9._-] becomes '_'. Two keys that
// differ only there share a file, which can only refuse a start, never allow a second daemon.
std::string file_name(const std::string& prefix, const std::string& key) {
  std::string name = prefix + "-";
  for (const char c : key) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                       c == '-' || c == '_';
    name += plain ? c : '_';
  }
  return name.substr(0, 240) + ".lock";
}

std::string canonical(const std::string& path) {
  char resolved[PATH_MAX];
  return realpath(path.c_str(), resolved) != nullptr ? std::string(resolved) : path;
}

std::string holder_of(int fd) {
  char buf[32] = {};
  const ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
  if (n <= 0) return "a process that has not written its pid yet";
  std::string pid(buf, static_cast<std::size_t>(n));
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return "pid " + pid;
}

std::string refusal(const std::string& holder, const LockedResource& res, const std::string& path) {
  return "hsad: another hsad (" + holder + ") already drives " + res.what + " (lock " + path + "); stop it first";
}

}  // namespace

std::vector<LockedResource> resources_of(const DaemonConfig& config, const std::vector<PlannedDriver>& drivers) {
  std::vector<LockedResource> r;
  const std::string path = canonical(config.source);
  r.push_back({"configuration " + path, file_name("config", path)});
  // The network an axis's commands travel on: group and port for udpm, the URL for another
  // provider (memq:// is this process only, so never shared).
  std::string network = config.lcm_url, network_key = config.lcm_url;
  if (const auto address = udpm_address(config.lcm_url)) {
    network = "LCM group " + address->group + " port " + std::to_string(address->port);
    network_key = address->group + "-" + std::to_string(address->port);
  }
  for (const AxisConfig& a : config.axes) {
    r.push_back({"axis " + a.name + " on " + network, file_name("axis", network_key + "-" + a.name)});
  }
  for (const PlannedDriver& d : drivers) {
    for (const std::string& device : d.plan.devices) {
      r.push_back({"I/O " + device + " (driver '" + d.name + "')", file_name("io", device)});
    }
  }
  return r;
}

std::string held_resource(const std::string& dir, const std::vector<LockedResource>& resources) {
  for (const LockedResource& res : resources) {
    const std::string path = dir + "/" + res.file;
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;  // never locked here, or not readable: InstanceLock says which when it starts
    // A shared lock is refused exactly while an hsad holds the exclusive one.
    const bool held = flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    const std::string holder = held ? holder_of(fd) : "";
    close(fd);
    if (held) return refusal(holder, res, path);
  }
  return "";
}

InstanceLock::InstanceLock(const std::string& dir, const std::vector<LockedResource>& resources) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("hsad: cannot create the lock directory " + dir + ": " + ec.message());
  for (const LockedResource& res : resources) {
    const std::string path = dir + "/" + res.file;
    const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
      const int err = errno;
      release();
      throw std::runtime_error("hsad: cannot open the lock file " + path + " for " + res.what + ": " +
                               std::strerror(err));
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string holder = err == EWOULDBLOCK ? holder_of(fd) : "";
      close(fd);
      release();
      if (err == EWOULDBLOCK) throw std::runtime_error(refusal(holder, res, path));
      throw std::runtime_error("hsad: cannot lock " + path + ": " + std::strerror(err));
    }
    fds_.push_back(fd);
    const std::string pid = std::to_string(getpid()) + "\n";
    // A failed write loses only the holder's pid in a later refusal: the lock holds anyway.
    const bool pid_written =
        ftruncate(fd, 0) == 0 && pwrite(fd, pid.data(), pid.size(), 0) == static_cast<ssize_t>(pid.size());
    (void)pid_written;
  }
}

InstanceLock::~InstanceLock() { release(); }

void InstanceLock::release() noexcept {
  for (const int fd : fds_) close(fd);
  fds_.clear();
}

}  // namespace hsa::daemon
