// The socket guard (lcm_socket_guard.hpp): while it is armed for a port, a UDP socket bound to that
// port carries the receive filter from its bind on, so a fragment sent to it never arrives; other
// ports, other socket types and binds after disarming are left alone; verify() refuses a socket on
// the port without the filter. This test executable, like hsad, links the guard's bind(). Plain UDP
// sockets on 127.0.0.1, no multicast.
#include "daemon/lcm_bridge/lcm_socket_guard.hpp"

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>
#include <string>

#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

namespace hsa::daemon {
namespace {

class Socket {
 public:
  explicit Socket(int type = SOCK_DGRAM) : fd_(socket(AF_INET, type | SOCK_CLOEXEC, 0)) {}
  ~Socket() { close(fd_); }
  int fd() const { return fd_; }

  // Binds to 127.0.0.1:`port` (0: any free port) through the process's bind(); returns its result.
  int bind_to(std::uint16_t port) const {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(port);
    return bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  }
  std::uint16_t port() const {
    sockaddr_in addr{};
    socklen_t len = sizeof addr;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    return ntohs(addr.sin_port);
  }

 private:
  int fd_;
};

// A port no socket holds now (bound and released).
std::uint16_t free_port() {
  const Socket probe;
  probe.bind_to(0);
  return probe.port();
}

void send_to(std::uint16_t port, const std::string& datagram) {
  const Socket sender;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(port);
  ASSERT_EQ(sendto(sender.fd(), datagram.data(), datagram.size(), 0, reinterpret_cast<sockaddr*>(&addr), sizeof addr),
            static_cast<ssize_t>(datagram.size()));
}

// The next datagram `s` receives within 2 s, or "".
std::string next(const Socket& s) {
  pollfd p{s.fd(), POLLIN, 0};
  if (poll(&p, 1, 2000) != 1) return "";
  char buf[2048];
  const ssize_t n = recv(s.fd(), buf, sizeof buf, 0);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : "";
}

const std::string kFragment = "LC03" + std::string(100, 'f');
const std::string kShortMessage = "LC02" + std::string(100, 's');

TEST(LcmSocketGuard, AUdpSocketBoundToTheArmedPortIsFilteredFromItsBindOn) {
  const std::uint16_t port = free_port();
  const LcmSocketGuard guard(port);
  const Socket lcm_socket;
  ASSERT_EQ(lcm_socket.bind_to(port), 0);
  EXPECT_TRUE(has_receive_filter(lcm_socket.fd()));
  send_to(port, kFragment);
  send_to(port, kShortMessage);
  EXPECT_EQ(next(lcm_socket), kShortMessage) << "the fragment reached the socket";
  EXPECT_NO_THROW(guard.verify());
}

TEST(LcmSocketGuard, OtherPortsOtherSocketTypesAndLaterBindsAreLeftAlone) {
  const std::uint16_t port = free_port();
  {
    const LcmSocketGuard guard(port);
    const Socket other_port;
    ASSERT_EQ(other_port.bind_to(free_port()), 0);
    EXPECT_FALSE(has_receive_filter(other_port.fd()));
    const Socket tcp(SOCK_STREAM);
    ASSERT_EQ(tcp.bind_to(port), 0);
    EXPECT_FALSE(has_receive_filter(tcp.fd()));
  }
  const Socket after;
  ASSERT_EQ(after.bind_to(port), 0);
  EXPECT_FALSE(has_receive_filter(after.fd())) << "disarmed, the guard still filtered";
  send_to(port, kFragment);
  EXPECT_EQ(next(after), kFragment);
}

TEST(LcmSocketGuard, StaysArmedUntilItsLastGuardGoes) {
  const std::uint16_t port = free_port();
  const LcmSocketGuard first(port);
  {
    const LcmSocketGuard second(port);
  }
  const Socket s;
  ASSERT_EQ(s.bind_to(port), 0);
  EXPECT_TRUE(has_receive_filter(s.fd()));
}

TEST(LcmSocketGuard, VerifyRefusesASocketOnThePortWithoutTheFilter) {
  const std::uint16_t port = free_port();
  {
    const LcmSocketGuard guard(port);
    EXPECT_THROW(guard.verify(), std::runtime_error) << "no socket on the port at all";
  }
  const Socket early;  // bound before the guard was armed: it could receive unfiltered
  int one = 1;
  ASSERT_EQ(setsockopt(early.fd(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one), 0);
  ASSERT_EQ(early.bind_to(port), 0);
  const LcmSocketGuard guard(port);
  const Socket late;
  ASSERT_EQ(setsockopt(late.fd(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one), 0);
  ASSERT_EQ(late.bind_to(port), 0);
  try {
    guard.verify();
    FAIL() << "verify() accepted an unfiltered socket";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("1 of 2 sockets bound to LCM's port " + std::to_string(port) +
                                               " have no receive filter"));
  }
}

}  // namespace
}  // namespace hsa::daemon
