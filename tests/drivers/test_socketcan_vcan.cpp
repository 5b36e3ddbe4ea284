// The socketcan plugin on a real CAN kernel: the plugin loaded as the daemon loads it, talking to
// a virtual CAN interface (vcan0) where an independent raw socket and can-utils' candump are its
// peers. Built as kernel_socketcan_vcan; the real-kernel harness (tests/kernel/) runs it inside a
// qemu VM, because the build machine's kernel has no CAN.
//
// Environment:
//   HSA_CAN_IFACE   the CAN interface to use (default vcan0); it must exist and be up
//   HSA_PLUGIN_DIR  where libhsa_driver_socketcan.so is (default: this build's plugin directory)
//   PATH            must find candump (can-utils)
// Exit status: gtest's (0 pass, 1 fail), or 77 (skip) when this kernel has no AF_CAN or the
// interface does not exist, after printing why. Times: the driver's staleness is judged on the
// cycle times the test passes to read(), so nothing here depends on how fast the VM runs; every
// wait for the kernel or candump is bounded.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dlfcn.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_error.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/socketcan_test_frames.hpp"
#include "tests/support/counting_allocator.hpp"

extern char** environ;

// Fault injection for the output watchdog: this binary exports its own send() (linked with
// --export-dynamic-symbol=send), so the plugin it dlopens calls it instead of libc's. While a test
// holds it (SendHold), a send() from any thread but the test's own waits until the test lets it
// go: the plugin's watchdog thread is then stopped inside its sending of the safe frames, as a
// normal-priority thread preempted there by the SCHED_FIFO RT thread would be. Every other call,
// and every call of the test's own thread, goes straight to libc.
namespace send_hold {
std::atomic<bool> armed{false};
std::atomic<bool> holding{false};
std::atomic<bool> released{false};
std::atomic<pid_t> test_thread{0};
}  // namespace send_hold

extern "C" ssize_t send(int fd, const void* buffer, size_t length, int flags) {
  using Send = ssize_t (*)(int, const void*, size_t, int);
  static const Send libc_send = reinterpret_cast<Send>(dlsym(RTLD_NEXT, "send"));
  if (send_hold::armed.load() && gettid() != send_hold::test_thread.load()) {
    send_hold::holding.store(true);
    // Bounded, so that a test that fails before it lets go cannot hang the run.
    for (int i = 0; i < 100'000 && !send_hold::released.load(); ++i) usleep(100);
    send_hold::holding.store(false);
  }
  return libc_send(fd, buffer, length, flags);
}

namespace hsa::io {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

std::string iface() {
  const char* name = std::getenv("HSA_CAN_IFACE");
  return name != nullptr && *name != '\0' ? name : "vcan0";
}

std::string plugin_dir() {
  const char* dir = std::getenv("HSA_PLUGIN_DIR");
  return dir != nullptr && *dir != '\0' ? dir : HSA_PLUGIN_DIR;
}

// The tests' frame map (socketcan_test_frames.hpp), the encoder stale after 50 ms, then whatever
// `extra_frames` adds.
std::string settings(const std::string& interface, const std::string& extra_frames = "") {
  return socketcan_test::frame_map("interface = \"" + interface + "\"\nmax_frames_per_read = 64\n", 0.05) +
         extra_frames;
}

// An independent raw CAN socket on the interface: the plugin's peer.
class Peer {
 public:
  explicit Peer(const std::vector<can_filter>& filters = {}) {
    fd_ = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) throw std::runtime_error("peer socket: " + std::string(std::strerror(errno)));
    // No filters: receive nothing (the peer only sends) unless told what to listen to.
    setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters.empty() ? nullptr : filters.data(),
               static_cast<socklen_t>(filters.size() * sizeof(can_filter)));
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(if_nametoindex(iface().c_str()));
    if (bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      throw std::runtime_error("peer bind: " + std::string(std::strerror(errno)));
    }
  }
  ~Peer() { close(fd_); }
  Peer(const Peer&) = delete;
  Peer& operator=(const Peer&) = delete;

  // Sends a classic frame; returns errno, 0 on success.
  int send(canid_t id, std::initializer_list<std::uint8_t> data) {
    can_frame f{};
    f.can_id = id;
    f.len = static_cast<std::uint8_t>(data.size());
    if (data.size() > 0) std::memcpy(f.data, data.begin(), data.size());
    return ::send(fd_, &f, sizeof f, 0) == static_cast<ssize_t>(sizeof f) ? 0 : errno;
  }

  // The next frame within `timeout`, or a frame with can_id 0 and len 0.
  can_frame receive(std::chrono::milliseconds timeout) {
    pollfd p{fd_, POLLIN, 0};
    can_frame f{};
    if (poll(&p, 1, static_cast<int>(timeout.count())) == 1 && recv(fd_, &f, sizeof f, 0) == sizeof f) return f;
    return can_frame{};
  }

  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

// Calls `step` every millisecond until `done` holds or `timeout` passes.
bool within(std::chrono::milliseconds timeout, const std::function<bool()>& done,
            const std::function<void()>& step = [] {}) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    step();
    if (done()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

class SocketCanVcan : public ::testing::Test {
 protected:
  void SetUp() override {
    can = loader.load_driver("can", "socketcan", toml::parse(settings(iface())));
    encoder = *can->find_channel("encoder");
    temperature = *can->find_channel("temperature");
    current_cmd = *can->find_channel("current_cmd");
    enable = *can->find_channel("enable");
    length_errors = *can->find_channel("length_errors");
    error_frames = *can->find_channel("error_frames");
    bus_off = *can->find_channel("bus_off");
  }

  ChannelSlot& slot(std::size_t i) { return can->slots()[i]; }

  // Reads at cycle time `t` until `done` holds (bounded: the kernel delivers within microseconds).
  bool read_until(Timestamp t, const std::function<bool()>& done) {
    return within(2000ms, done, [&] { (void)can->read(t, 1ms); });
  }

  PluginLoader loader{{plugin_dir()}};
  std::unique_ptr<DriverHandle> can;
  std::size_t encoder = 0, temperature = 0, current_cmd = 0, enable = 0, length_errors = 0, error_frames = 0,
              bus_off = 0;
  Peer peer;
};

TEST_F(SocketCanVcan, ReadsFramesAnotherSocketSends) {
  ASSERT_EQ(can->read(1ms, 1ms), IoStatus::ok);
  EXPECT_EQ(slot(encoder).status, SampleStatus::disconnected);
  ASSERT_EQ(peer.send(0x181, {0xC0, 0x1D, 0xFE, 0xFF}), 0);         // -123456 µm
  ASSERT_EQ(peer.send(0x18FF0001 | CAN_EFF_FLAG, {0x01, 0x2C}), 0);  // 300 * 0.1
  ASSERT_TRUE(read_until(2ms, [&] {
    return slot(encoder).status == SampleStatus::ok && slot(temperature).status == SampleStatus::ok;
  }));
  EXPECT_DOUBLE_EQ(slot(encoder).value, -0.123456);
  EXPECT_EQ(slot(encoder).timestamp, 2ms);
  EXPECT_DOUBLE_EQ(slot(temperature).value, 30.0);
  EXPECT_EQ(slot(length_errors).value, 0.0);
}

TEST_F(SocketCanVcan, TheKernelFilterDropsOtherIds) {
  // Frames of other ids never reach the plugin's socket, so even a flood of them cannot crowd
  // the encoder out of a bounded drain: 200 foreign frames, then one encoder frame, all drained
  // by reads of at most 64 frames each.
  for (int i = 0; i < 200; ++i) ASSERT_EQ(peer.send(0x180, {1, 2, 3, 4}), 0);
  ASSERT_EQ(peer.send(0x181 | CAN_EFF_FLAG, {1, 2, 3, 4}), 0);  // same number, extended: another id
  ASSERT_EQ(peer.send(0x181, {0x10, 0, 0, 0}), 0);
  ASSERT_EQ(can->read(1ms, 1ms), IoStatus::ok);
  EXPECT_EQ(slot(encoder).status, SampleStatus::ok) << "the encoder frame was not in the first 64 frames";
  EXPECT_DOUBLE_EQ(slot(encoder).value, 16e-6);
  EXPECT_EQ(slot(length_errors).value, 0.0);
}

// candump (can-utils) as a second, independent receiver: its output for one frame of `id`, in
// its log format "(time) vcan0 201#05DC01", while `step` runs every millisecond. Empty when
// candump saw nothing within its own 2 s timeout.
std::string candump_one(const std::string& filter, const std::function<void()>& step) {
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) return "pipe failed";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  const std::string target = iface() + "," + filter;
  const char* argv[] = {"candump", "-L", "-T", "2000", "-n", "1", target.c_str(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "candump", &actions, nullptr, const_cast<char**>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  if (spawned != 0) {
    close(out[0]);
    ADD_FAILURE() << "cannot run candump (can-utils) from PATH: " << std::strerror(spawned);
    return {};
  }
  fcntl(out[0], F_SETFL, O_NONBLOCK);
  std::string text;
  int status = 0;
  const bool exited = within(5000ms, [&] {
    char buffer[256];
    for (ssize_t n; (n = ::read(out[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
    return waitpid(pid, &status, WNOHANG) == pid;
  }, step);
  if (!exited) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  char buffer[256];
  for (ssize_t n; (n = ::read(out[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
  close(out[0]);
  return text;
}

TEST_F(SocketCanVcan, WritesACurrentFrameThatCandumpSees) {
  ASSERT_TRUE(can->activate());
  slot(current_cmd).value = 1.5;  // 1500 mA = 0x05DC
  slot(enable).value = 1.0;
  // Keep the cycle going (one 10 ms send period per step) until candump has one frame: it may
  // start listening after the first frames went out.
  Timestamp t = 0ms;
  const std::string dump = candump_one("201:7FF", [&] {
    t += 10ms;
    ASSERT_EQ(can->write(t, 10ms), IoStatus::ok);
  });
  EXPECT_THAT(dump, HasSubstr(" " + iface() + " 201#05DC01")) << "candump printed: " << dump;
}

TEST_F(SocketCanVcan, SendsAtTheConfiguredPeriodOnly) {
  Peer listener({{0x201, CAN_SFF_MASK | CAN_EFF_FLAG}});
  ASSERT_TRUE(can->activate());
  slot(current_cmd).value = -2.0;  // -2000 mA = 0xF830
  for (int ms = 0; ms <= 30; ++ms) ASSERT_EQ(can->write(ms * 1ms, 1ms), IoStatus::ok);  // at 0, 10, 20, 30
  int frames = 0;
  for (can_frame f = listener.receive(200ms); f.len != 0; f = listener.receive(50ms)) {
    ++frames;
    EXPECT_EQ(f.can_id, 0x201u);
    EXPECT_EQ(f.len, 3);
    EXPECT_EQ(f.data[0], 0xF8);
    EXPECT_EQ(f.data[1], 0x30);
    EXPECT_EQ(f.data[2], 0x00);
  }
  EXPECT_EQ(frames, 4);
}

TEST_F(SocketCanVcan, GoesStaleWhenFramesStop) {
  ASSERT_EQ(peer.send(0x181, {0x10, 0, 0, 0}), 0);
  ASSERT_TRUE(read_until(1000ms, [&] { return slot(encoder).status == SampleStatus::ok; }));
  // No more frames: on the cycle's own clock the sample ages past max_age_s = 50 ms.
  ASSERT_EQ(can->read(1050ms, 1ms), IoStatus::ok);
  EXPECT_EQ(slot(encoder).status, SampleStatus::ok);
  ASSERT_EQ(can->read(1051ms, 1ms), IoStatus::ok);
  EXPECT_EQ(slot(encoder).status, SampleStatus::stale);
  EXPECT_DOUBLE_EQ(slot(encoder).value, 16e-6);
  EXPECT_EQ(slot(encoder).timestamp, 1000ms);
  ASSERT_EQ(can->read(2000ms, 1ms), IoStatus::ok);
  EXPECT_EQ(slot(encoder).status, SampleStatus::stale);
  // Frames again: fresh again.
  ASSERT_EQ(peer.send(0x181, {0x20, 0, 0, 0}), 0);
  ASSERT_TRUE(read_until(2100ms, [&] { return slot(encoder).status == SampleStatus::ok; }));
  EXPECT_DOUBLE_EQ(slot(encoder).value, 32e-6);
}

TEST_F(SocketCanVcan, AFrameOfTheWrongLengthIsRejectedAndCounted) {
  ASSERT_EQ(peer.send(0x181, {0x10, 0, 0, 0}), 0);
  ASSERT_TRUE(read_until(1ms, [&] { return slot(encoder).status == SampleStatus::ok; }));
  ASSERT_EQ(peer.send(0x181, {0xFF, 0xFF, 0xFF}), 0);  // 3 bytes instead of 4
  ASSERT_TRUE(read_until(2ms, [&] { return slot(length_errors).value == 1.0; }));
  EXPECT_DOUBLE_EQ(slot(encoder).value, 16e-6);  // unchanged
  EXPECT_EQ(slot(encoder).status, SampleStatus::stale);
  EXPECT_EQ(slot(encoder).timestamp, 1ms);
  ASSERT_EQ(peer.send(0x181, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}), 0);  // 8 bytes
  ASSERT_TRUE(read_until(3ms, [&] { return slot(length_errors).value == 2.0; }));
  EXPECT_DOUBLE_EQ(slot(encoder).value, 16e-6);
  EXPECT_EQ(slot(encoder).status, SampleStatus::stale);
  EXPECT_EQ(can->state(), DriverState::inactive);  // a bad frame is not a driver error
  ASSERT_EQ(peer.send(0x181, {0x20, 0, 0, 0}), 0);
  ASSERT_TRUE(read_until(4ms, [&] { return slot(encoder).status == SampleStatus::ok; }));
  EXPECT_DOUBLE_EQ(slot(encoder).value, 32e-6);
}

TEST_F(SocketCanVcan, ABusOffErrorFrameIsADriverError) {
  // vcan has no controller to go bus-off, but the CAN core delivers an error frame sent by
  // another socket to every socket whose CAN_RAW_ERR_FILTER matches, as a controller's would be.
  const int sent = peer.send(CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_WARNING, 0, 0, 0, 0, 0, 0});
  if (sent != 0) GTEST_SKIP() << "this kernel refuses to send error frames: " << std::strerror(sent);
  ASSERT_TRUE(read_until(1ms, [&] { return slot(error_frames).value == 1.0; }));
  EXPECT_EQ(slot(bus_off).value, 0.0);
  EXPECT_EQ(can->state(), DriverState::inactive);  // a warning is counted, not a fault
  ASSERT_EQ(peer.send(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0}), 0);
  ASSERT_TRUE(within(2000ms, [&] { return can->read(2ms, 1ms) == IoStatus::error; }));
  EXPECT_EQ(can->state(), DriverState::error);
  EXPECT_EQ(slot(bus_off).value, 1.0);
  EXPECT_EQ(slot(error_frames).value, 2.0);
  // Recovery closes the socket and configures a fresh one, back to the state the driver failed in.
  ASSERT_TRUE(can->recover(toml::parse(settings(iface()))));
  EXPECT_EQ(can->state(), DriverState::inactive);
  ASSERT_EQ(can->read(3ms, 1ms), IoStatus::ok);
}

TEST_F(SocketCanVcan, DeactivateSendsTheSafeFrame) {
  Peer listener({{0x201, CAN_SFF_MASK | CAN_EFF_FLAG}});
  ASSERT_TRUE(can->activate());
  slot(current_cmd).value = 1.5;
  slot(enable).value = 1.0;
  ASSERT_EQ(can->write(0ms, 1ms), IoStatus::ok);
  ASSERT_TRUE(can->deactivate());
  const can_frame command = listener.receive(2000ms);
  EXPECT_EQ(command.data[0], 0x05);
  const can_frame safe = listener.receive(2000ms);
  EXPECT_EQ(safe.can_id, 0x201u);
  ASSERT_EQ(safe.len, 3);
  EXPECT_EQ(safe.data[0], 0xFF);  // -250 mA = 0xFF06
  EXPECT_EQ(safe.data[1], 0x06);
  EXPECT_EQ(safe.data[2], 0x00);  // enable off
  EXPECT_EQ(listener.receive(50ms).len, 0);  // once
}

// Holds the other threads' send() calls (see send_hold above) from construction to release().
class SendHold {
 public:
  SendHold() {
    send_hold::released.store(false);
    send_hold::test_thread.store(gettid());
    send_hold::armed.store(true);
  }
  ~SendHold() { release(); }
  SendHold(const SendHold&) = delete;
  SendHold& operator=(const SendHold&) = delete;

  // True once another thread is held inside send().
  bool wait_until_holding(std::chrono::milliseconds timeout) {
    return within(timeout, [] { return send_hold::holding.load(); });
  }
  void release() {
    send_hold::released.store(true);
    send_hold::armed.store(false);
    (void)within(2000ms, [] { return !send_hold::holding.load(); });
  }
};

// make_safe puts the safe frame on the bus before it returns, whatever the output watchdog is
// doing. Here the watchdog has timed out (no write() for output_timeout_s) and is held inside its
// own sending of the safe frames, flag raised, as when the RT thread preempts it there: nothing of
// the watchdog's can reach the bus, so a safe frame seen now is make_safe's.
TEST_F(SocketCanVcan, MakeSafeSendsTheSafeFrameAtOnceWhileTheWatchdogIsHeldInItsSend) {
  Peer listener({{0x201, CAN_SFF_MASK | CAN_EFF_FLAG}});
  ASSERT_TRUE(can->activate());
  // The watchdog's clock starts at the first write() it sees after it saw the driver go live: give
  // it a few of its ticks (output_timeout_s / 4) to see that first.
  std::this_thread::sleep_for(50ms);
  slot(current_cmd).value = 1.5;
  slot(enable).value = 1.0;
  ASSERT_EQ(can->write(0ms, 1ms), IoStatus::ok);
  const can_frame command = listener.receive(2000ms);
  ASSERT_EQ(command.len, 3);
  EXPECT_EQ(command.data[0], 0x05);

  SendHold hold;  // no more write(): the watchdog times out after 5 ms and stops in its send()
  ASSERT_TRUE(hold.wait_until_holding(2000ms)) << "the watchdog never sent the safe frames";
  EXPECT_EQ(listener.receive(50ms).len, 0) << "a frame got past the held watchdog";

  can->make_safe();
  const can_frame safe = listener.receive(1000ms);  // the watchdog is still held: make_safe's own
  EXPECT_TRUE(send_hold::holding.load());
  ASSERT_EQ(safe.len, 3) << "no safe frame after make_safe while the watchdog was held";
  EXPECT_EQ(safe.can_id, 0x201u);
  EXPECT_EQ(safe.data[0], 0xFF);  // -250 mA = 0xFF06
  EXPECT_EQ(safe.data[1], 0x06);
  EXPECT_EQ(safe.data[2], 0x00);  // enable off

  // Let go: the watchdog's safe frame follows, and it keeps repeating them (write() is latched).
  hold.release();
  const can_frame repeated = listener.receive(2000ms);
  ASSERT_EQ(repeated.len, 3);
  EXPECT_EQ(repeated.data[2], 0x00);
  EXPECT_EQ(can->write(1ms, 1ms), IoStatus::ok);  // latched safe: sends nothing
  for (int i = 0; i < 10; ++i) {  // the watchdog's repeats, every output_timeout_s
    const can_frame f = listener.receive(2000ms);
    ASSERT_EQ(f.len, 3);
    EXPECT_EQ(f.data[0], 0xFF) << "a command frame after make_safe";
    EXPECT_EQ(f.data[2], 0x00);
  }
}

TEST_F(SocketCanVcan, ReadAndWriteAllocateNothing) {
  ASSERT_TRUE(can->activate());
  ASSERT_EQ(can->read(0ms, 1ms), IoStatus::ok);
  ASSERT_EQ(can->write(0ms, 1ms), IoStatus::ok);
  const long before = hsa::test::process_allocations();
  for (int i = 1; i <= 500; ++i) {
    ASSERT_EQ(peer.send(0x181, {static_cast<std::uint8_t>(i), 0, 0, 0}), 0);
    if (i % 50 == 0) {
      ASSERT_EQ(peer.send(0x181, {1, 2}), 0);
    }
    ASSERT_EQ(can->read(i * 1ms, 1ms), IoStatus::ok);
    slot(current_cmd).value = 0.001 * i;
    ASSERT_EQ(can->write(i * 1ms, 1ms), IoStatus::ok);
  }
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
  EXPECT_GT(slot(length_errors).value, 0.0);
}

std::string configure_error(const std::string& text) {
  const PluginLoader loader({plugin_dir()});
  try {
    (void)loader.load_driver("can", "socketcan", toml::parse(text));
  } catch (const PluginError& e) {
    return e.what();
  }
  return "(configured)";
}

TEST(SocketCanVcanConfigure, AMissingInterfaceIsNamed) {
  EXPECT_THAT(configure_error(settings("nocan7")), HasSubstr("no network interface 'nocan7'"));
  EXPECT_THAT(configure_error(settings("lo")), HasSubstr("interface 'lo' is not a CAN interface"));
}

// A CAN FD input frame of 12 bytes with a channel in bytes 8..11.
const std::string fd_frame = R"(
[[frames]]
id = 0x300
fd = true
direction = "input"
length = 12
[[frames.channels]]
name = "wide"
kind = "analog_input"
byte_offset = 8
bytes = 4
)";

// Runs a command from PATH to completion (bounded to 5 s); its exit code, or -1 when it could
// not run or did not finish.
int run(std::initializer_list<const char*> args) {
  std::vector<char*> argv;
  for (const char* a : args) argv.push_back(const_cast<char*>(a));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  int status = 0;
  if (!within(5000ms, [&] { return waitpid(pid, &status, WNOHANG) == pid; })) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SocketCanVcanConfigure, ADownInterfaceIsNamedAndGoingDownIsADriverError) {
  // A scratch interface of its own, so vcan0 stays up for the other tests.
  const char* scratch = "hsacan9";
  if (run({"ip", "link", "add", "dev", scratch, "type", "vcan"}) != 0) {
    GTEST_SKIP() << "cannot create a vcan interface (needs ip from iproute2 or busybox, and CAP_NET_ADMIN)";
  }
  struct Remove {
    const char* name;
    ~Remove() { (void)run({"ip", "link", "del", "dev", name}); }
  } remove{scratch};
  EXPECT_THAT(configure_error(settings(scratch)), HasSubstr("CAN interface 'hsacan9' is down"));
  // Classic CAN only (vcan's MTU decides): a CAN FD frame is refused at configure.
  ASSERT_EQ(run({"ip", "link", "set", scratch, "mtu", "16"}), 0);
  ASSERT_EQ(run({"ip", "link", "set", scratch, "up"}), 0);
  EXPECT_THAT(configure_error(settings(scratch, fd_frame)),
              HasSubstr("frames[3] (frame 0x300) is a CAN FD frame, but interface 'hsacan9' has MTU 16"));
  const PluginLoader loader({plugin_dir()});
  auto can = loader.load_driver("can", "socketcan", toml::parse(settings(scratch)));
  ASSERT_TRUE(can->activate());
  ASSERT_EQ(can->read(1ms, 1ms), IoStatus::ok);
  ASSERT_EQ(can->write(1ms, 1ms), IoStatus::ok);
  ASSERT_EQ(run({"ip", "link", "set", scratch, "down"}), 0);
  // The kernel reports ENETDOWN on the socket: the next read is a driver error.
  EXPECT_EQ(can->read(2ms, 1ms), IoStatus::error);
  EXPECT_EQ(can->state(), DriverState::error);
  // While the interface is down a recovery cannot configure, and the driver stays in error;
  // once it is up again, the recovery brings the driver back active.
  const Result down = can->recover(toml::parse(settings(scratch)));
  EXPECT_FALSE(down);
  EXPECT_NE(down.message().find("down"), std::string::npos) << down.message();
  EXPECT_EQ(can->state(), DriverState::error);
  ASSERT_EQ(run({"ip", "link", "set", scratch, "up"}), 0);
  ASSERT_TRUE(can->recover(toml::parse(settings(scratch))));
  EXPECT_EQ(can->state(), DriverState::active);
  EXPECT_EQ(can->read(3ms, 1ms), IoStatus::ok);
}

TEST(SocketCanVcanConfigure, CanFdFrameIsReadOnAnFdInterfaceAndRefusedOnAClassicOne) {
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, iface().c_str(), IFNAMSIZ - 1);
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  ASSERT_EQ(ioctl(fd, SIOCGIFMTU, &ifr), 0);
  close(fd);
  if (ifr.ifr_mtu == static_cast<int>(CANFD_MTU)) {
    // An FD interface: the FD frame is received.
    const PluginLoader loader({plugin_dir()});
    auto can = loader.load_driver("can", "socketcan", toml::parse(settings(iface(), fd_frame)));
    const int peer = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    const int on = 1;
    setsockopt(peer, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(if_nametoindex(iface().c_str()));
    ASSERT_EQ(bind(peer, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
    canfd_frame f{};
    f.can_id = 0x300;
    f.len = 12;
    f.data[8] = 0x2A;
    ASSERT_EQ(send(peer, &f, CANFD_MTU, 0), static_cast<ssize_t>(CANFD_MTU));
    close(peer);
    const std::size_t wide = *can->find_channel("wide");
    ASSERT_TRUE(within(2000ms, [&] { return can->slots()[wide].status == SampleStatus::ok; },
                       [&] { (void)can->read(1ms, 1ms); }));
    EXPECT_EQ(can->slots()[wide].value, 42.0);
  } else {
    EXPECT_THAT(configure_error(settings(iface(), fd_frame)),
                HasSubstr("frames[3] (frame 0x300) is a CAN FD frame, but interface '" + iface() + "' has MTU " +
                          std::to_string(ifr.ifr_mtu)));
  }
}

std::string simdev_path() {
  const char* env = std::getenv("HSA_SIMDEV");
  return env != nullptr && *env != '\0' ? env : HSA_SIMDEV;
}

// hsa-simdev --can on the interface, its stdout read until it serves CAN (bounded); stopped with
// SIGTERM (SIGKILL after 5 s) at the end of the test.
class SimdevCan {
 public:
  explicit SimdevCan(const std::vector<std::string>& extra = {}) {
    const std::string simdev = simdev_path();
    const std::string can = iface();
    std::vector<std::string> args{simdev, "--port", "0", "--can", can, "--duration", "30", "--initial-position-m", "0.15"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    int out[2];
    if (pipe2(out, O_CLOEXEC) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    const int spawned = posix_spawn(&pid_, simdev.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(out[1]);
    fd_ = out[0];
    if (spawned != 0) {
      pid_ = 0;
      return;
    }
    fcntl(fd_, F_SETFL, O_NONBLOCK);
    serving_ = within(10000ms, [&] {
      char buffer[256];
      for (ssize_t n; (n = ::read(fd_, buffer, sizeof buffer)) > 0;) banner_.append(buffer, static_cast<std::size_t>(n));
      return banner_.find("communication watchdog") != std::string::npos;
    });
  }
  ~SimdevCan() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      int status = 0;
      if (!within(5000ms, [&] { return waitpid(pid_, &status, WNOHANG) == pid_; })) {
        kill(pid_, SIGKILL);
        waitpid(pid_, &status, 0);
      }
    }
    if (fd_ >= 0) close(fd_);
  }
  SimdevCan(const SimdevCan&) = delete;
  SimdevCan& operator=(const SimdevCan&) = delete;

  [[nodiscard]] bool serving() const { return serving_ && banner_.find("serving CAN") != std::string::npos; }
  [[nodiscard]] const std::string& banner() const { return banner_; }

 private:
  pid_t pid_ = 0;
  int fd_ = -1;
  bool serving_ = false;
  std::string banner_;
};

// hsa-simdev --can: the simulated rig's encoder and valve on the bus (tools/hsa_simdev/
// can_server.hpp). The plugin closes a proportional position loop on it through vcan0: 10 mm up
// from where the rod starts. Skipped when hsa-simdev is not there ($HSA_SIMDEV, else this build's).
TEST(SocketCanVcanSimdev, ClosesAPositionLoopOnTheSimulatedRigOverCan) {
  if (access(simdev_path().c_str(), X_OK) != 0) GTEST_SKIP() << "no hsa-simdev at " << simdev_path() << " (set HSA_SIMDEV)";
  const SimdevCan simdev;
  ASSERT_TRUE(simdev.serving()) << "hsa-simdev printed: " << simdev.banner();
  const std::string can = iface();

  const PluginLoader loader({plugin_dir()});
  auto driver = loader.load_driver("can", "socketcan", toml::parse("interface = \"" + can + "\"\n" + R"(
[[frames]]
id = 0x181
direction = "input"
length = 4
max_age_s = 0.05
[[frames.channels]]
name = "encoder"
kind = "encoder_input"
byte_offset = 0
bytes = 4
signed = true
scale = 1e-6
unit = "m"
[[frames]]
id = 0x201
direction = "output"
length = 3
[[frames.channels]]
name = "valve_cmd"
kind = "analog_output"
byte_offset = 0
bytes = 2
signed = true
scale = 1e-4
safe_value = 0.0
[[frames.channels]]
name = "valve_enable"
kind = "digital_output"
byte_offset = 2
)"));
  const std::size_t encoder = *driver->find_channel("encoder");
  const std::size_t command = *driver->find_channel("valve_cmd");
  const std::size_t enable = *driver->find_channel("valve_enable");
  ASSERT_TRUE(driver->activate());
  Timestamp t{};
  const auto cycle = [&] { t += 1ms; (void)driver->read(t, 1ms); };
  ASSERT_TRUE(within(5000ms, [&] { return driver->slots()[encoder].status == SampleStatus::ok; }, cycle))
      << "no encoder frame from hsa-simdev";
  const double start = driver->slots()[encoder].value;
  EXPECT_NEAR(start, 0.15, 0.005);
  const double target = start + 0.01;
  int settled = 0;
  const bool reached = within(10000ms, [&] { return settled >= 100; }, [&] {
    cycle();
    const ChannelSlot& position = driver->slots()[encoder];
    const double error = target - position.value;
    driver->slots()[command].value = std::clamp(85.0 * error, -0.3, 0.3);  // P loop, opening per metre
    driver->slots()[enable].value = 1.0;
    ASSERT_EQ(driver->write(t, 1ms), IoStatus::ok);
    settled = position.status == SampleStatus::ok && std::abs(error) < 0.0005 ? settled + 1 : 0;
  });
  EXPECT_TRUE(reached) << "rod at " << driver->slots()[encoder].value << " m, target " << target << " m";
  ASSERT_TRUE(driver->deactivate());  // valve centred and disabled
}

// The newest frame on `peer`'s socket: what is queued is drained, then the next one to arrive
// (within 2 s) is returned, so it was sent after this call began. len 0 when none arrived.
can_frame fresh(Peer& peer) {
  for (int n = 0; n < 100000 && peer.receive(0ms).len != 0; ++n) {
  }
  return peer.receive(2000ms);
}

double position_m(const can_frame& f) {
  std::int32_t counts = 0;
  std::memcpy(&counts, f.data, sizeof counts);  // little-endian, as is x86
  return counts * 1e-6;
}

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// hsa-simdev's communication watchdog on CAN (can_server.hpp): valve frames (0x201) sent every
// 2 ms by a raw socket hold the command; when they stop, the status frame (0x281) shows the trip
// no sooner than the watchdog time after the last frame, and the rod stops; frames with the enable
// on do not clear the latch, a frame with the enable off does, and the valve then moves the rod
// again. How fast the rod moves is measured in the same run and only compared.
TEST(SocketCanVcanSimdev, WatchdogTripsWhenValveFramesStopAndTheEnableOffClearsIt) {
  if (access(simdev_path().c_str(), X_OK) != 0) GTEST_SKIP() << "no hsa-simdev at " << simdev_path() << " (set HSA_SIMDEV)";
  const SimdevCan simdev;
  ASSERT_TRUE(simdev.serving()) << "hsa-simdev printed: " << simdev.banner();
  const auto at = simdev.banner().find("communication watchdog ");
  ASSERT_NE(at, std::string::npos) << simdev.banner();
  const int w = std::atoi(simdev.banner().c_str() + at + std::strlen("communication watchdog "));
  ASSERT_GT(w, 0) << "the watchdog is on by default: " << simdev.banner();
  EXPECT_LE(w, 100);

  Peer master;
  Peer status({{0x281, CAN_SFF_MASK | CAN_EFF_FLAG}});
  Peer position({{0x181, CAN_SFF_MASK | CAN_EFF_FLAG}});
  // Opening 0.1 = 1000 counts = 0x03E8, little-endian.
  const auto command = [&](bool enable) { return master.send(0x201, {0xE8, 0x03, static_cast<std::uint8_t>(enable ? 1 : 0)}); };
  // Sends valve frames every 2 ms for `duration`; returns the longest span from the start of one
  // send to the end of the next (the most the device can have gone without a frame), and leaves
  // the start of the last send in `last`.
  Clock::time_point last{};
  const auto keep_sending = [&](bool enable, std::chrono::milliseconds duration) {
    double longest = 0.0;
    last = Clock::now();
    EXPECT_EQ(command(enable), 0);
    const auto until = Clock::now() + duration;
    while (Clock::now() < until) {
      std::this_thread::sleep_for(2ms);
      const auto start = Clock::now();
      EXPECT_EQ(command(enable), 0);
      longest = std::max(longest, ms_between(last, Clock::now()));
      last = start;
    }
    return longest;
  };
  const auto rod = [&] {
    const can_frame f = fresh(position);
    EXPECT_EQ(f.len, 4) << "no position frame";
    return position_m(f);
  };

  const can_frame idle = fresh(status);
  ASSERT_EQ(idle.len, 2) << "no status frame";
  EXPECT_EQ(idle.data[0], 0);  // not tripped
  EXPECT_EQ(idle.data[1], 0);  // no trips yet

  // Commanded: the rod moves, and while frames come every 2 ms the watchdog holds.
  const double x0 = rod();
  const double longest = keep_sending(true, std::chrono::milliseconds(5 * w));
  const double x1 = rod();
  const can_frame holding = fresh(status);
  const double moved = std::abs(x1 - x0);
  EXPECT_GT(moved, 0.0005) << "the command did not move the rod";
  if (longest < w) {
    EXPECT_EQ(holding.data[0], 0) << "tripped although no frame was more than " << longest << " ms after the last";
  } else {
    std::printf("note: this test stalled %.1f ms between two frames (watchdog %d ms); no-trip check skipped\n",
                longest, w);
  }

  // Silence: tripped no sooner than w after the last frame; the rod then stays where it is.
  can_frame tripped{};
  ASSERT_TRUE(within(5000ms, [&] {
    tripped = fresh(status);
    return tripped.len == 2 && (tripped.data[0] & 1) != 0;
  })) << "the watchdog never tripped";
  const double trip_ms = ms_between(last, Clock::now());
  std::printf("watchdog %d ms: the status frame showed the trip %.1f ms after the last valve frame\n", w, trip_ms);
  EXPECT_GE(trip_ms, w) << "tripped early";
  EXPECT_EQ(tripped.data[1], holding.data[1] + 1) << "one more trip";
  const double x2 = rod();
  std::this_thread::sleep_for(std::chrono::milliseconds(5 * w));
  const double x3 = rod();
  EXPECT_LT(std::abs(x3 - x2), moved / 10) << "the valve still moves the rod after the trip";

  // Latched: frames with the enable on are held at the safe command.
  (void)keep_sending(true, std::chrono::milliseconds(2 * w));
  const double x4 = rod();
  EXPECT_LT(std::abs(x4 - x3), moved / 10) << "a latched valve moved";
  EXPECT_EQ(fresh(status).data[0] & 1, 1);

  // A frame with the enable off clears it; then the valve obeys again.
  ASSERT_EQ(command(false), 0);
  const double x5 = rod();
  const double longest_after = keep_sending(true, std::chrono::milliseconds(5 * w));
  const double x6 = rod();
  const can_frame cleared = fresh(status);
  if (longest_after < w) {
    EXPECT_EQ(cleared.data[0] & 1, 0) << "the latch did not clear";
  }
  EXPECT_GT(std::abs(x6 - x5), moved / 2) << "the valve did not obey after the latch was cleared";
}

// --watchdog-ms 0: the last valve frame holds, as before there was a watchdog.
TEST(SocketCanVcanSimdev, WatchdogOffKeepsTheLastCommand) {
  if (access(simdev_path().c_str(), X_OK) != 0) GTEST_SKIP() << "no hsa-simdev at " << simdev_path() << " (set HSA_SIMDEV)";
  const SimdevCan simdev({"--watchdog-ms", "0"});
  ASSERT_TRUE(simdev.serving()) << "hsa-simdev printed: " << simdev.banner();
  EXPECT_NE(simdev.banner().find("communication watchdog off"), std::string::npos) << simdev.banner();
  Peer master;
  Peer status({{0x281, CAN_SFF_MASK | CAN_EFF_FLAG}});
  Peer position({{0x181, CAN_SFF_MASK | CAN_EFF_FLAG}});
  ASSERT_EQ(master.send(0x201, {0xE8, 0x03, 1}), 0);
  const double x0 = position_m(fresh(position));
  std::this_thread::sleep_for(300ms);  // three default watchdog times with no frame
  const double x1 = position_m(fresh(position));
  const can_frame s = fresh(status);
  ASSERT_EQ(s.len, 2);
  EXPECT_EQ(s.data[0], 0);
  EXPECT_EQ(s.data[1], 0);
  EXPECT_GT(x1 - x0, 0.0005) << "the rod should keep moving on the last command";
}

}  // namespace
}  // namespace hsa::io

int main(int argc, char** argv) {
  const std::string name = hsa::io::iface();
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) {
    std::printf("kernel_socketcan_vcan: SKIP: no CAN in this kernel: socket(PF_CAN, SOCK_RAW, CAN_RAW): %s\n",
                std::strerror(errno));
    return 77;
  }
  close(fd);
  if (if_nametoindex(name.c_str()) == 0) {
    std::printf("kernel_socketcan_vcan: SKIP: no CAN interface '%s' (set HSA_CAN_IFACE, or: ip link add dev "
                "vcan0 type vcan && ip link set vcan0 up)\n",
                name.c_str());
    return 77;
  }
  std::printf("kernel_socketcan_vcan: interface %s, plugins from %s\n", name.c_str(), hsa::io::plugin_dir().c_str());
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
