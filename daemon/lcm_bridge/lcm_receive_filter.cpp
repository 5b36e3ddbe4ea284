#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

#include <linux/filter.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

namespace hsa::daemon {
namespace {

// "LC02", LCM's magic of an unfragmented message, as the filter loads it (network order).
constexpr std::uint32_t kShortMessageMagic = 0x4c433032;
// A UDP socket's filter sees the datagram from its UDP header on.
constexpr std::uint32_t kUdpHeader = 8;
constexpr std::size_t kProgramLength = 6;

std::array<sock_filter, kProgramLength> program(std::size_t max_datagram) {
  return {{
      BPF_STMT(BPF_LD | BPF_W | BPF_LEN, 0),
      BPF_JUMP(BPF_JMP | BPF_JGT | BPF_K, static_cast<std::uint32_t>(kUdpHeader + max_datagram), 3, 0),
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kUdpHeader),
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kShortMessageMagic, 0, 1),
      BPF_STMT(BPF_RET | BPF_K, 0xffffffffu),  // pass the whole datagram
      BPF_STMT(BPF_RET | BPF_K, 0),            // drop it
  }};
}

bool bound_to(int fd, std::uint16_t port) {
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISSOCK(st.st_mode)) return false;
  int type = 0;
  socklen_t len = sizeof type;
  if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_DGRAM) return false;
  sockaddr_in addr{};
  len = sizeof addr;
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0 || addr.sin_family != AF_INET) return false;
  return ntohs(addr.sin_port) == port;
}

}  // namespace

int attach_receive_filter(int fd, std::size_t max_datagram) noexcept {
  auto code = program(max_datagram);
  const sock_fprog fprog{static_cast<unsigned short>(code.size()), code.data()};
  return setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) == 0 ? 0 : errno;
}

bool has_receive_filter(int fd, std::size_t max_datagram) {
  // SO_GET_FILTER's length is in instructions, not bytes.
  std::array<sock_filter, kProgramLength + 1> attached{};
  socklen_t length = attached.size();
  if (getsockopt(fd, SOL_SOCKET, SO_GET_FILTER, attached.data(), &length) != 0 || length != kProgramLength) {
    return false;
  }
  const auto expected = program(max_datagram);
  return std::memcmp(attached.data(), expected.data(), sizeof expected) == 0;
}

ReceiveSockets receive_sockets(std::uint16_t port, std::size_t max_datagram) {
  ReceiveSockets found;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    const std::string name = entry.path().filename().string();
    char* end = nullptr;
    const long fd = std::strtol(name.c_str(), &end, 10);
    if (*end != '\0' || !bound_to(static_cast<int>(fd), port)) continue;
    ++found.bound;
    if (has_receive_filter(static_cast<int>(fd), max_datagram)) ++found.filtered;
  }
  return found;
}

}  // namespace hsa::daemon
