#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

#include <linux/filter.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace hsa::daemon {
namespace {

// "LC02", LCM's magic of an unfragmented message, as the filter loads it (network order).
constexpr std::uint32_t kShortMessageMagic = 0x4c433032;
// A UDP socket's filter sees the datagram from its UDP header on.
constexpr std::uint32_t kUdpHeader = 8;

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

std::optional<std::uint16_t> udpm_port(std::string_view url) {
  constexpr std::string_view scheme = "udpm://";
  if (url.substr(0, scheme.size()) != scheme) return std::nullopt;
  std::string_view rest = url.substr(scheme.size());
  rest = rest.substr(0, rest.find('?'));
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string_view::npos) return std::uint16_t{7667};
  unsigned value = 0;
  const std::string_view digits = rest.substr(colon + 1);
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc{} || end != digits.data() + digits.size() || value == 0 || value > 65535) {
    throw std::invalid_argument("LCM URL '" + std::string(url) + "': bad port '" + std::string(digits) + "'");
  }
  return static_cast<std::uint16_t>(value);
}

std::size_t limit_lcm_receive(std::uint16_t port, std::size_t max_datagram) {
  sock_filter code[] = {
      BPF_STMT(BPF_LD | BPF_W | BPF_LEN, 0),
      BPF_JUMP(BPF_JMP | BPF_JGT | BPF_K, static_cast<std::uint32_t>(kUdpHeader + max_datagram), 3, 0),
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kUdpHeader),
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, kShortMessageMagic, 0, 1),
      BPF_STMT(BPF_RET | BPF_K, 0xffffffffu),  // pass the whole datagram
      BPF_STMT(BPF_RET | BPF_K, 0),            // drop it
  };
  const sock_fprog program{static_cast<unsigned short>(std::size(code)), code};
  std::size_t filtered = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    const std::string name = entry.path().filename().string();
    char* end = nullptr;
    const long fd = std::strtol(name.c_str(), &end, 10);
    if (*end != '\0' || !bound_to(static_cast<int>(fd), port)) continue;
    if (setsockopt(static_cast<int>(fd), SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) != 0) {
      throw std::runtime_error("cannot attach the receive filter to LCM's socket on port " + std::to_string(port) +
                               ": " + std::strerror(errno));
    }
    ++filtered;
  }
  return filtered;
}

}  // namespace hsa::daemon
