#include "daemon/lcm_bridge/lcm_socket_guard.hpp"

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

namespace hsa::daemon {
namespace {

// The armed ports, each with how many guards armed it. Slots are written under the mutex and read
// without it in bind(): a port is armed before LCM can bind to it and disarmed after LCM's sockets
// are gone, so bind() never races with a change that matters to it.
constexpr std::size_t kMaxArmedPorts = 16;
struct ArmedPort {
  std::atomic<std::uint32_t> port{0};  // 0: free
  std::uint32_t guards = 0;            // under arming_mutex
};
std::array<ArmedPort, kMaxArmedPorts> armed_ports;
std::mutex arming_mutex;

bool armed(std::uint16_t port) noexcept {
  for (const ArmedPort& slot : armed_ports) {
    if (slot.port.load(std::memory_order_acquire) == port) return true;
  }
  return false;
}

// The port `addr` binds an IPv4 datagram socket to, or 0 for any other bind.
std::uint16_t udp_port_of(int fd, const sockaddr* addr, socklen_t len) noexcept {
  if (addr == nullptr || len < static_cast<socklen_t>(sizeof(sockaddr_in)) || addr->sa_family != AF_INET) return 0;
  int type = 0;
  socklen_t type_len = sizeof type;
  if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &type_len) != 0 || type != SOCK_DGRAM) return 0;
  sockaddr_in in{};
  std::memcpy(&in, addr, sizeof in);
  return ntohs(in.sin_port);
}

}  // namespace

LcmSocketGuard::LcmSocketGuard(std::uint16_t port) : port_(port) {
  if (port == 0) throw std::invalid_argument("LcmSocketGuard: port 0");
  const std::lock_guard lock(arming_mutex);
  ArmedPort* free_slot = nullptr;
  for (ArmedPort& slot : armed_ports) {
    if (slot.port.load(std::memory_order_relaxed) == port) {
      ++slot.guards;
      return;
    }
    if (free_slot == nullptr && slot.port.load(std::memory_order_relaxed) == 0) free_slot = &slot;
  }
  if (free_slot == nullptr) {
    throw std::runtime_error("LcmSocketGuard: more than " + std::to_string(kMaxArmedPorts) + " LCM ports at once");
  }
  free_slot->guards = 1;
  free_slot->port.store(port, std::memory_order_release);
}

LcmSocketGuard::~LcmSocketGuard() {
  const std::lock_guard lock(arming_mutex);
  for (ArmedPort& slot : armed_ports) {
    if (slot.port.load(std::memory_order_relaxed) == port_ && --slot.guards == 0) {
      slot.port.store(0, std::memory_order_release);
    }
  }
}

void LcmSocketGuard::verify() const {
  const ReceiveSockets found = receive_sockets(port_);
  if (found.bound == 0) {
    throw std::runtime_error("LcmBridge: LCM's receive socket on port " + std::to_string(port_) +
                             " was not found, so its receive filter cannot be checked");
  }
  if (found.filtered != found.bound) {
    throw std::runtime_error("LcmBridge: " + std::to_string(found.bound - found.filtered) + " of " + std::to_string(found.bound) +
                             " sockets bound to LCM's port " + std::to_string(port_) +
                             " have no receive filter: this executable's bind() did not take LCM's "
                             "(lcm_socket_guard.hpp)");
  }
}

}  // namespace hsa::daemon

// The interposed bind (see the header). The C library's bind is this system call on every Linux
// architecture hsa builds for.
extern "C" int bind(int fd, const sockaddr* addr, socklen_t len) {
  const std::uint16_t port = hsa::daemon::udp_port_of(fd, addr, len);
  if (port != 0 && hsa::daemon::armed(port)) {
    if (const int err = hsa::daemon::attach_receive_filter(fd); err != 0) {
      errno = err;
      return -1;
    }
  }
  return static_cast<int>(syscall(SYS_bind, fd, addr, len));
}
