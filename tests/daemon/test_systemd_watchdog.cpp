// The watchdog pings systemd only while the RT heartbeat advances with no gap over the bound. systemd is played by a unix
// datagram socket named in NOTIFY_SOCKET, which is all sd_notify talks to.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "daemon/service/systemd_watchdog.hpp"

namespace hsa::daemon {
namespace {

class FakeSystemd {
 public:
  FakeSystemd() : path_("/tmp/hsa-notify-" + std::to_string(getpid())) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    path_.copy(addr.sun_path, sizeof(addr.sun_path) - 1);
    unlink(path_.c_str());
    if (bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) ADD_FAILURE() << "bind " << path_;
    timeval timeout{0, 100'000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    setenv("NOTIFY_SOCKET", path_.c_str(), 1);
  }
  ~FakeSystemd() {
    unsetenv("NOTIFY_SOCKET");
    close(fd_);
    unlink(path_.c_str());
  }
  // Every datagram received so far (waits at most 100 ms for the next one).
  std::vector<std::string> drain() {
    std::vector<std::string> out;
    char buf[512];
    for (ssize_t n; (n = recv(fd_, buf, sizeof(buf), 0)) > 0;) out.emplace_back(buf, static_cast<std::size_t>(n));
    return out;
  }

 private:
  std::string path_;
  int fd_ = -1;
};

int count(const std::vector<std::string>& messages, const std::string& what) {
  int n = 0;
  for (const auto& m : messages) n += m.find(what) != std::string::npos;
  return n;
}

// Waits for a condition with a generous bound; the test asserts behaviour, not timing.
template <typename F>
bool eventually(F condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

TEST(SystemdWatchdog, ReadyCarriesTheStatusText) {
  FakeSystemd systemd;
  SystemdWatchdog watchdog;
  watchdog.notify_ready("2 axes running");
  const auto messages = systemd.drain();
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("READY=1"), std::string::npos);
  EXPECT_NE(messages[0].find("STATUS=2 axes running"), std::string::npos);
}

TEST(SystemdWatchdog, PingsOnlyWhileTheHeartbeatAdvances) {
  FakeSystemd systemd;
  SystemdWatchdog watchdog(std::chrono::milliseconds(10));
  std::atomic<bool> beating{true};
  std::thread rt([&] {
    while (beating) {
      watchdog.heartbeat(std::chrono::steady_clock::now().time_since_epoch().count());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  watchdog.start();
  ASSERT_TRUE(eventually([&] { return watchdog.pings_sent() >= 3; }));
  beating = false;
  rt.join();
  // Once the heartbeat stops, at most the check already under way may still ping.
  const std::uint64_t pings_at_stall = watchdog.pings_sent();
  ASSERT_TRUE(eventually([&] { return watchdog.stalls_seen() >= 3; }));
  watchdog.stop();
  EXPECT_LE(watchdog.pings_sent(), pings_at_stall + 1);

  const auto messages = systemd.drain();
  EXPECT_EQ(count(messages, "WATCHDOG=1"), static_cast<int>(watchdog.pings_sent()));
}

// The heartbeat is scripted on a synthetic clock and the checks are made by hand, in order: no
// thread, no wall-clock threshold. Cycles 1 ms apart with a 5 ms bound; one interval holds a
// single 50 ms gap among regular cycles and gets no ping, the intervals around it do.
TEST(SystemdWatchdog, AnIntervalWithOneLongGapIsNotPinged) {
  FakeSystemd systemd;
  SystemdWatchdog watchdog(std::chrono::milliseconds(100));
  watchdog.set_max_gap(std::chrono::milliseconds(5));
  constexpr std::int64_t kMs = 1'000'000;
  std::int64_t t = 0;
  const auto beat_for = [&](int cycles) {
    for (int i = 0; i < cycles; ++i) {
      watchdog.heartbeat(t);
      t += kMs;
    }
  };

  beat_for(100);
  EXPECT_TRUE(watchdog.check());  // regular cycles: ping

  beat_for(20);
  t += 49 * kMs;  // one gap of 50 ms between two cycles, then regular cycles again
  beat_for(30);
  EXPECT_FALSE(watchdog.check());  // the heartbeat advanced, but not in time

  beat_for(100);
  EXPECT_TRUE(watchdog.check());  // on time again: pinged again

  // A gap that spans a check is judged in the interval its second heartbeat falls in.
  beat_for(10);
  EXPECT_TRUE(watchdog.check());
  t += 49 * kMs;
  beat_for(10);
  EXPECT_FALSE(watchdog.check());

  EXPECT_FALSE(watchdog.check());  // no heartbeat at all: no ping
  EXPECT_EQ(watchdog.pings_sent(), 3u);
  EXPECT_EQ(watchdog.stalls_seen(), 3u);
  const auto messages = systemd.drain();
  EXPECT_EQ(count(messages, "WATCHDOG=1"), 3);
}

// A gap exactly at the bound is within it; one nanosecond more is not.
TEST(SystemdWatchdog, TheBoundIsInclusive) {
  FakeSystemd systemd;
  SystemdWatchdog watchdog(std::chrono::milliseconds(100));
  watchdog.set_max_gap(std::chrono::milliseconds(5));
  watchdog.heartbeat(0);
  watchdog.heartbeat(5'000'000);
  EXPECT_TRUE(watchdog.check());
  watchdog.heartbeat(10'000'001);
  EXPECT_FALSE(watchdog.check());
}

}  // namespace
}  // namespace hsa::daemon
