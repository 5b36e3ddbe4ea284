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

// The endpoint named by a driver's settings, or "" when it has none hsad knows of.
std::string endpoint_of(const DriverConfig& d) {
  const toml::table& s = d.settings;
  if (const auto v = s["interface"].value<std::string>()) return "can:" + *v;
  if (const auto v = s["device"].value<std::string>()) return "serial:" + canonical(*v);
  if (const auto host = s["host"].value<std::string>()) {
    return "tcp:" + *host + ":" + std::to_string(s["port"].value_or<std::int64_t>(0));
  }
  return "";
}

std::string holder_of(int fd) {
  char buf[32] = {};
  const ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
  if (n <= 0) return "a process that has not written its pid yet";
  std::string pid(buf, static_cast<std::size_t>(n));
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return "pid " + pid;
}

}  // namespace

std::vector<LockedResource> resources_of(const DaemonConfig& config) {
  std::vector<LockedResource> r;
  const std::string path = canonical(config.source);
  r.push_back({"configuration " + path, file_name("config", path)});
  for (const AxisConfig& a : config.axes) {
    r.push_back({"axis " + a.name + " on " + config.lcm_url, file_name("axis", config.lcm_url + "-" + a.name)});
  }
  for (const DriverConfig& d : config.drivers) {
    const std::string endpoint = endpoint_of(d);
    if (!endpoint.empty()) r.push_back({"I/O " + endpoint + " (driver '" + d.name + "')", file_name("io", endpoint)});
  }
  return r;
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
      if (err == EWOULDBLOCK) {
        throw std::runtime_error("hsad: another hsad (" + holder + ") already drives " + res.what + " (lock " +
                                 path + "); stop it first");
      }
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
