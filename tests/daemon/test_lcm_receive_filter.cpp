// The receive filter on LCM's sockets (lcm_receive_filter.hpp): an unfragmented LCM datagram of
// hsad's size passes; a fragment, an oversized datagram and junk never reach the socket; the
// sockets on a port and which of them carry the filter are found. Run on plain UDP sockets on
// 127.0.0.1, so no multicast is involved.
#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

namespace hsa::daemon {
namespace {

class Socket {
 public:
  Socket() : fd_(socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {}
  ~Socket() { close(fd_); }
  int fd() const { return fd_; }

 private:
  int fd_;
};

class ReceiveFilterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_GE(receiver_.fd(), 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(bind(receiver_.fd(), reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    socklen_t len = sizeof addr_;
    ASSERT_EQ(getsockname(receiver_.fd(), reinterpret_cast<sockaddr*>(&addr_), &len), 0);
  }

  void send(const std::string& datagram) {
    ASSERT_EQ(sendto(sender_.fd(), datagram.data(), datagram.size(), 0, reinterpret_cast<sockaddr*>(&addr_),
                     sizeof addr_),
              static_cast<ssize_t>(datagram.size()));
  }

  // The next datagram the receiver gets, waiting at most 5 s ("" if none came).
  std::string next() {
    pollfd p{receiver_.fd(), POLLIN, 0};
    if (poll(&p, 1, 5000) != 1) return "";
    char buf[70000];
    const ssize_t n = recv(receiver_.fd(), buf, sizeof buf, 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : "";
  }

  std::uint16_t port() const { return ntohs(addr_.sin_port); }

  static std::string short_message(std::size_t size) { return "LC02" + std::string(size - 4, 'x'); }

  Socket receiver_, sender_;
  sockaddr_in addr_{};
};

TEST_F(ReceiveFilterTest, WithoutTheFilterEverythingArrives) {
  // The control case: the datagrams the filter must drop do reach an unfiltered socket.
  send("LC03" + std::string(200, 'f'));
  EXPECT_EQ(next().substr(0, 4), "LC03");
}

TEST_F(ReceiveFilterTest, OnlyShortMessagesUpToTheLimitReachTheSocket) {
  ASSERT_EQ(attach_receive_filter(receiver_.fd(), 1000), 0);
  EXPECT_TRUE(has_receive_filter(receiver_.fd(), 1000));
  send("LC03" + std::string(200, 'f'));  // a fragment, as a forged header would come
  send(short_message(1001));             // one byte over the limit
  send("junk that is not LCM");
  send(std::string(3, 'L'));             // shorter than the magic
  send(short_message(1000));             // at the limit: the first to arrive
  send(short_message(20));
  EXPECT_EQ(next(), short_message(1000));
  EXPECT_EQ(next(), short_message(20));
}

TEST_F(ReceiveFilterTest, TheSocketsOnAPortAndTheirFiltersAreFound) {
  Socket other;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(other.fd(), reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ReceiveSockets found = receive_sockets(port());
  EXPECT_EQ(found.bound, 1u) << "only the receiver is bound to its port";
  EXPECT_EQ(found.filtered, 0u);
  EXPECT_FALSE(has_receive_filter(receiver_.fd()));
  ASSERT_EQ(attach_receive_filter(receiver_.fd()), 0);
  found = receive_sockets(port());
  EXPECT_EQ(found.filtered, 1u);
  // Another size limit is another filter: has_receive_filter compares the whole program.
  EXPECT_FALSE(has_receive_filter(receiver_.fd(), 1000));
}

}  // namespace
}  // namespace hsa::daemon
