#include "drivers/socketcan/can_socket.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace hsa::io::socketcan {
namespace {

std::string errno_text(int error) { return std::strerror(error); }

void set_option(int fd, int option, const void* value, socklen_t size, const char* what) {
  if (setsockopt(fd, SOL_CAN_RAW, option, value, size) != 0) {
    throw CanSocketError("setsockopt(" + std::string(what) + ") failed: " + errno_text(errno));
  }
}

}  // namespace

std::string socket_failure_message(int error) {
  if (error == EAFNOSUPPORT) {
    return "AF_CAN is not supported by this kernel (socket(PF_CAN, SOCK_RAW, CAN_RAW): " +
           errno_text(error) +
           "). It needs the kernel modules can and can-raw (modprobe can-raw), and can-dev with "
           "the interface's driver, or vcan for a virtual bus (modprobe vcan)";
  }
  if (error == EPROTONOSUPPORT) {
    return "this kernel has AF_CAN but not CAN_RAW sockets (" + errno_text(error) +
           "). Load the kernel module can-raw (modprobe can-raw)";
  }
  return "cannot open a raw CAN socket: " + errno_text(error);
}

CanSocket::CanSocket(const CanSettings& s) {
  fd_ = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) throw CanSocketError(socket_failure_message(errno));
  try {
    const std::string& name = s.interface;
    const unsigned index = if_nametoindex(name.c_str());
    if (index == 0) {
      throw CanSocketError("no network interface '" + name + "' (key 'interface'): " +
                           errno_text(errno) + ". Load its driver and set it up (ip link set " + name +
                           " up type can bitrate ...), or for a virtual bus: ip link add dev " + name +
                           " type vcan && ip link set " + name + " up");
    }
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, name.c_str(), IFNAMSIZ - 1);
    if (ioctl(fd_, SIOCGIFHWADDR, &ifr) == 0 && ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
      throw CanSocketError("interface '" + name + "' is not a CAN interface (key 'interface')");
    }
    if (ioctl(fd_, SIOCGIFFLAGS, &ifr) != 0) {
      throw CanSocketError("cannot read the flags of interface '" + name + "': " + errno_text(errno));
    }
    if ((ifr.ifr_flags & IFF_UP) == 0) {
      throw CanSocketError("CAN interface '" + name + "' is down (key 'interface'): bring it up first " +
                           "(ip link set " + name + " up, with type can bitrate ... for a real controller)");
    }

    std::vector<can_filter> filters;
    for (const FrameMap& f : s.frames) {
      if (f.direction != Direction::input) continue;
      // Match the id and the frame format exactly, and never remote frames.
      const canid_t mask = (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
      filters.push_back({f.can_id(), mask});
    }
    set_option(fd_, CAN_RAW_FILTER, filters.empty() ? nullptr : filters.data(),
               static_cast<socklen_t>(filters.size() * sizeof(can_filter)), "CAN_RAW_FILTER");
    const can_err_mask_t errors = CAN_ERR_MASK;
    set_option(fd_, CAN_RAW_ERR_FILTER, &errors, sizeof errors, "CAN_RAW_ERR_FILTER");

    if (s.uses_fd()) {
      if (ioctl(fd_, SIOCGIFMTU, &ifr) != 0) {
        throw CanSocketError("cannot read the MTU of interface '" + name + "': " + errno_text(errno));
      }
      if (ifr.ifr_mtu != static_cast<int>(CANFD_MTU)) {
        std::string frame;
        for (std::size_t i = 0; i < s.frames.size(); ++i) {
          if (s.frames[i].fd) {
            frame = "frames[" + std::to_string(i) + "] (" + s.frames[i].describe() + ")";
            break;
          }
        }
        throw CanSocketError("" + frame + " is a CAN FD frame, but interface '" + name +
                             "' has MTU " + std::to_string(ifr.ifr_mtu) + ": classic CAN only (CAN FD needs MTU " +
                             std::to_string(CANFD_MTU) + ": ip link set " + name +
                             " type can ... fd on, or for vcan: ip link set " + name + " mtu 72)");
      }
      const int on = 1;
      set_option(fd_, CAN_RAW_FD_FRAMES, &on, sizeof on, "CAN_RAW_FD_FRAMES");
    }

    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(index);
    if (bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      const int error = errno;
      if (error == ENODEV) {
        throw CanSocketError("interface '" + name + "' is not a CAN interface (key 'interface')");
      }
      throw CanSocketError("cannot bind to CAN interface '" + name + "': " + errno_text(error));
    }
  } catch (...) {
    close(fd_);
    fd_ = -1;
    throw;
  }
}

CanSocket::~CanSocket() {
  if (fd_ >= 0) close(fd_);
}

}  // namespace hsa::io::socketcan
