// Modbus timeouts on the real path: a device that stops answering, or answers
// too late, must give stale samples, counted link errors and a clear reason, never a blocked RT
// cycle or a silently wrong value. And a device that answers but refuses a command (exception 3)
// must give a write failure that says so. (A peer silent from the first request on is in
// test_modbus_pymodbus.cpp, ModbusTimeout.ASilentPeerGivesLinkErrorsAndNeverBlocksTheCycle.)
//
// The peer is a small Modbus TCP server written here on plain sockets (not libmodbus, which the
// plugin uses), so its misbehaviour is under the test's control: it answers, falls silent (reads
// requests and drops them), answers some requests only after the plugin's response timeout, or
// refuses every write of a value other than 0 with exception 3 (illegal data value).
// Input register a holds 1000 + a, so every value says which request it answers. Holding
// registers keep what is written. One thread per connection: the plugin reconnects while an
// old connection may still be sleeping on a late answer.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/modbus_driver_loop.hpp"
#include "tests/drivers/test_modbus_support.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using modbus_test::DriverLoop;
using modbus_test::tcp_link;
using modbus_test::wait_until;

constexpr Duration cycle_period = DriverLoop::cycle_period;
constexpr auto response_timeout = 50ms;  // the plugin's, set in settings() below

enum class Behaviour { answer, silent, late_every_third, refuse_nonzero_writes };

class MisbehavingPeer {
 public:
  MisbehavingPeer() {
    listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(modbus_test::free_tcp_port()));
    if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || listen(listen_fd_, 16) != 0) {
      throw std::runtime_error("cannot listen on 127.0.0.1");
    }
    port_ = ntohs(addr.sin_port);
    acceptor_ = std::jthread([this](std::stop_token stop) { accept_loop(stop); });
  }
  ~MisbehavingPeer() {
    acceptor_.request_stop();
    acceptor_.join();
    std::vector<std::jthread> connections;
    {
      const std::lock_guard lock(mutex_);
      connections.swap(connections_);
    }
    connections.clear();  // stops and joins, outside the lock the connections take
    close(listen_fd_);
  }
  MisbehavingPeer(const MisbehavingPeer&) = delete;
  MisbehavingPeer& operator=(const MisbehavingPeer&) = delete;

  [[nodiscard]] int port() const { return port_; }
  void set(Behaviour b) { behaviour_.store(b); }
  [[nodiscard]] int accepted() const { return accepted_.load(); }
  [[nodiscard]] int late_answers() const { return late_.load(); }

 private:
  static bool wait_readable(int fd, const std::stop_token& stop) {
    while (!stop.stop_requested()) {
      pollfd p{fd, POLLIN, 0};
      const int n = poll(&p, 1, 20);
      if (n > 0) return true;
      if (n < 0 && errno != EINTR) return false;
    }
    return false;
  }

  static bool read_exact(int fd, std::uint8_t* buf, std::size_t n, const std::stop_token& stop) {
    std::size_t got = 0;
    while (got < n) {
      if (!wait_readable(fd, stop)) return false;
      const ssize_t r = recv(fd, buf + got, n - got, 0);
      if (r <= 0) return false;
      got += static_cast<std::size_t>(r);
    }
    return true;
  }

  void accept_loop(const std::stop_token& stop) {
    while (wait_readable(listen_fd_, stop)) {
      const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) continue;
      accepted_.fetch_add(1);
      const std::lock_guard lock(mutex_);
      connections_.emplace_back([this, fd](std::stop_token s) {
        serve(fd, s);
        close(fd);
      });
    }
  }

  // One request, one answer (or none), until the client goes away.
  void serve(int fd, const std::stop_token& stop) {
    std::uint8_t header[7];
    std::uint8_t pdu[260];
    while (read_exact(fd, header, 7, stop)) {
      const std::size_t length = static_cast<std::size_t>(header[4] << 8 | header[5]);
      if (length < 2 || length - 1 > sizeof pdu || !read_exact(fd, pdu, length - 1, stop)) return;
      const int sequence = requests_.fetch_add(1);
      const Behaviour b = behaviour_.load();
      if (b == Behaviour::silent) continue;  // read and dropped: the client's timeout runs out
      if (b == Behaviour::late_every_third && sequence % 3 == 2) {
        // Well past the client's timeout, then the real answer, as a slow device would send it.
        std::this_thread::sleep_for(response_timeout * 3 / 2);
        late_.fetch_add(1);
      }
      std::vector<std::uint8_t> answer = respond(pdu, length - 1);
      std::vector<std::uint8_t> frame(header, header + 7);
      frame[4] = static_cast<std::uint8_t>((answer.size() + 1) >> 8);
      frame[5] = static_cast<std::uint8_t>(answer.size() + 1);
      frame.insert(frame.end(), answer.begin(), answer.end());
      if (send(fd, frame.data(), frame.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(frame.size())) return;
    }
  }

  std::vector<std::uint8_t> respond(const std::uint8_t* pdu, std::size_t n) {
    const std::uint8_t function = pdu[0];
    const int address = n >= 3 ? pdu[1] << 8 | pdu[2] : 0;
    const int count = n >= 5 ? pdu[3] << 8 | pdu[4] : 0;
    const auto exception = [&](std::uint8_t code) { return std::vector<std::uint8_t>{static_cast<std::uint8_t>(function | 0x80), code}; };
    const std::lock_guard lock(mutex_);
    switch (function) {
      case 0x03:    // read holding registers
      case 0x04: {  // read input registers
        if (n != 5 || count < 1 || count > 125 || address + count > 100) return exception(0x02);
        std::vector<std::uint8_t> a{function, static_cast<std::uint8_t>(2 * count)};
        for (int i = address; i < address + count; ++i) {
          const std::uint16_t v = function == 0x04 ? static_cast<std::uint16_t>(1000 + i) : holding_[i];
          a.push_back(static_cast<std::uint8_t>(v >> 8));
          a.push_back(static_cast<std::uint8_t>(v));
        }
        return a;
      }
      case 0x06:  // write single register: the answer echoes the request
        if (n != 5 || address >= 100) return exception(0x02);
        if (count != 0 && behaviour_.load() == Behaviour::refuse_nonzero_writes) return exception(0x03);
        holding_[address] = static_cast<std::uint16_t>(count);
        return {pdu, pdu + n};
      case 0x10:  // write multiple registers
        if (n < 6 || address + count > 100 || n != 6 + 2 * static_cast<std::size_t>(count)) return exception(0x02);
        for (int i = 0; i < count; ++i) holding_[address + i] = static_cast<std::uint16_t>(pdu[6 + 2 * i] << 8 | pdu[7 + 2 * i]);
        return {pdu, pdu + 5};
      default:
        return exception(0x01);
    }
  }

  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<Behaviour> behaviour_{Behaviour::answer};
  std::atomic<int> requests_{0};
  std::atomic<int> accepted_{0};
  std::atomic<int> late_{0};
  std::mutex mutex_;  // connections_ and holding_
  std::uint16_t holding_[100] = {};
  std::vector<std::jthread> connections_;
  std::jthread acceptor_;  // last: stopped before the members it uses go
};

// The link to the peer, with the plugin's response timeout (response_timeout above).
std::string settings(int port, const std::string& channels) { return tcp_link(port, 0.05, 0.2) + channels; }

// Every channel here is one plain 16-bit register or bit.
std::string channel(const std::string& name, const std::string& kind, const std::string& table, int address) {
  return modbus_test::channel(name, kind, table, address, "type = \"uint16\"\n");
}

TEST(ModbusTimeout, APeerFallingSilentMidRunGivesStaleSamplesKeepingTheLastGoodValue) {
  MisbehavingPeer peer;
  DriverLoop loop(settings(peer.port(), channel("a", "analog_input", "input_register", 3)));
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(loop.slot("a").value, 1003.0);

  // Connected, but nothing comes back: every transaction runs into the response timeout.
  peer.set(Behaviour::silent);
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::stale; }, 3s));
  EXPECT_EQ(loop.slot("a").value, 1003.0);  // the last good value, marked stale: never made up
  const Timestamp stamp = loop.slot("a").timestamp;
  // The plugin gives up on the connection after each timeout and opens a new one (the peer
  // accepts it): both the errors and the reconnects show.
  const int accepted = peer.accepted();
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("link_errors").value >= 3 && peer.accepted() > accepted; }, 5s))
      << "link_errors " << loop.slot("link_errors").value << ", connections " << peer.accepted();
  EXPECT_EQ(loop.slot("transaction_errors").value, 0.0);  // no answer is not a bad answer
  EXPECT_EQ(loop.slot("a").status, SampleStatus::stale);
  EXPECT_EQ(loop.slot("a").timestamp, stamp);  // the old sample is not passed off as new

  // The device answers again: fresh samples on the (re)opened link, nothing to reset.
  peer.set(Behaviour::answer);
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::ok; }, 5s));
  EXPECT_EQ(loop.slot("a").value, 1003.0);
  EXPECT_NE(loop.slot("a").timestamp, stamp);
  EXPECT_EQ(loop.slot("link_up").value, 1.0);
}

// The counter of one name in the driver's health, or -1 when it has none of that name.
std::int64_t health_counter(const DriverHandle& driver, const std::string& name) {
  for (const auto& [n, value] : driver.health().counters) {
    if (n == name) return static_cast<std::int64_t>(value);
  }
  return -1;
}

// A device that stops answering still takes connections (a stopped process, a hung stack): its
// link is "not answering", with its timeouts counted, through every reconnect; distinct from a
// link that is down because nobody takes the connection.
TEST(ModbusTimeout, APeerThatStopsAnsweringIsNotAnsweringAndADeadOneIsDown) {
  auto peer = std::make_unique<MisbehavingPeer>();
  DriverLoop loop(settings(peer->port(), channel("a", "analog_input", "input_register", 3)));
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(loop.driver->health().link, DriverHealth::Link::up);
  EXPECT_EQ(health_counter(*loop.driver, "timeouts"), 0);

  peer->set(Behaviour::silent);
  const int accepted = peer->accepted();
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("link_errors").value >= 3 && peer->accepted() > accepted + 1; }, 5s))
      << "link_errors " << loop.slot("link_errors").value << ", connections " << peer->accepted();
  // Sampled over many cycles, reconnects included: never up while the device is silent.
  for (int i = 0; i < 50; ++i) {
    loop.cycle();
    ASSERT_EQ(loop.driver->health().link, DriverHealth::Link::not_answering) << i;
    ASSERT_EQ(loop.slot("link_up").value, 0.0) << i;
  }
  const std::int64_t timeouts = health_counter(*loop.driver, "timeouts");
  EXPECT_GE(timeouts, 3);
  EXPECT_EQ(timeouts, health_counter(*loop.driver, "link_errors"));  // every link error was one
  EXPECT_THAT(loop.driver->health().last_error,
              ::testing::HasSubstr("Connection timed out reading input registers 3..3"));

  // Nobody takes the connection any more: down, refused, and no more timeouts.
  peer.reset();
  ASSERT_TRUE(loop.run_until([&] { return loop.driver->health().link == DriverHealth::Link::down; }, 5s));
  ASSERT_TRUE(loop.run_until([&] {
    return loop.driver->health().last_error.find("Connection refused") != std::string::npos;
  }, 5s)) << loop.driver->health().last_error;
  EXPECT_EQ(loop.slot("link_up").value, 0.0);
}

// A device that takes the safe values but refuses a command: the bus thread sees the exception,
// the RT side learns of it at its next read, and the failure is named the write's, with the
// device's code and the register block.
TEST(ModbusRefusedWrite, ARefusedCommandIsAWriteFailureWithTheCodeAndTheBlock) {
  MisbehavingPeer peer;
  peer.set(Behaviour::refuse_nonzero_writes);
  DriverLoop loop(settings(peer.port(), channel("cmd", "analog_output", "holding_register", 7)));
  ASSERT_TRUE(loop.driver->activate().ok());  // its safe value, 0, is taken
  loop.slot("cmd").value = 5.0;
  IoStatus status = IoStatus::ok;
  ASSERT_TRUE(wait_until([&] {
    loop.t = loop.now();
    status = loop.driver->read(loop.t, cycle_period);
    if (status == IoStatus::ok) status = loop.driver->write(loop.t, cycle_period);
    return status != IoStatus::ok;
  }, 3s)) << "the refused command never became a driver error";
  EXPECT_EQ(status, IoStatus::write_error);
  EXPECT_EQ(loop.driver->state(), DriverState::error);
  EXPECT_EQ(loop.driver->failure_reason(),
            "write failed: Modbus exception 3 (Illegal data value) writing holding registers 7..7 of Modbus TCP "
            "127.0.0.1:" + std::to_string(peer.port()));
}

TEST(ModbusTimeout, LateAnswersAreNeverTakenForALaterRequest) {
  MisbehavingPeer peer;
  // Two blocks, so two requests a cycle whose answers look alike but for their values: a late
  // answer for one taken as the answer to the next would show as the other's value.
  DriverLoop loop(settings(peer.port(), channel("a", "analog_input", "input_register", 0) +
                                      channel("b", "analog_input", "input_register", 10) +
                                      channel("c", "analog_input", "input_register", 20)));
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("c").status == SampleStatus::ok; }, 3s));
  peer.set(Behaviour::late_every_third);
  int wrong = 0;
  int fresh = 0;
  Timestamp last{};
  const auto check = [&] {
    for (const auto& [name, expected] : {std::pair{"a", 1000.0}, {"b", 1010.0}, {"c", 1020.0}}) {
      if (loop.slot(name).value != expected) ++wrong;
    }
    if (loop.slot("b").timestamp != last) ++fresh;
    last = loop.slot("b").timestamp;
  };
  ASSERT_TRUE(loop.run_until([&] { return peer.late_answers() >= 6 && loop.slot("link_errors").value >= 6; }, 10s, check))
      << "late answers " << peer.late_answers() << ", link_errors " << loop.slot("link_errors").value;
  EXPECT_EQ(wrong, 0) << "a value that belongs to another request reached the RT side";
  EXPECT_GT(fresh, 3);  // between the late answers, requests were answered and delivered
  EXPECT_EQ(loop.slot("transaction_errors").value, 0.0);
}

TEST(ModbusTimeout, DeactivatingAgainstASilentDeviceFailsWithTheLinkAndTheReason) {
  MisbehavingPeer peer;
  DriverLoop loop(settings(peer.port(), channel("cmd", "analog_output", "holding_register", 0) +
                                      channel("back", "analog_input", "holding_register", 5)));
  ASSERT_TRUE(loop.driver->activate().ok());
  loop.slot("cmd").value = 42.0;
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("back").status == SampleStatus::ok; }, 3s));
  peer.set(Behaviour::silent);
  // The safe value cannot be confirmed on the device: deactivate says so, naming the link and
  // libmodbus's reason, instead of pretending the outputs are safe.
  const Result r = loop.driver->deactivate();
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("127.0.0.1:" + std::to_string(peer.port())), std::string::npos) << r.message();
  EXPECT_NE(r.message().find("timed out"), std::string::npos) << r.message();
  EXPECT_EQ(loop.driver->state(), DriverState::inactive);
}

TEST(ModbusTimeout, TheErrorCountersSurviveTheDriversRecovery) {
  MisbehavingPeer peer;
  const std::string text = settings(peer.port(), channel("a", "analog_input", "input_register", 3));
  DriverLoop loop(text);
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::ok; }, 3s));
  peer.set(Behaviour::silent);
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("link_errors").value >= 2; }, 5s));
  const double before = loop.slot("link_errors").value;
  peer.set(Behaviour::answer);

  // What hsad's recovery does to the driver: a new bus thread on a new link. The errors that led
  // to it stay counted, in the slots and in the health that status shows.
  ASSERT_TRUE(loop.driver->cleanup().ok());
  ASSERT_TRUE(loop.driver->configure(toml::parse(text)).ok());
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("a").status == SampleStatus::ok; }, 3s));
  EXPECT_GE(loop.slot("link_errors").value, before);
  std::uint64_t health_errors = 0;
  for (const auto& [name, value] : loop.driver->health().counters) {
    if (name == "link_errors") health_errors = value;
  }
  EXPECT_GE(static_cast<double>(health_errors), before);
}

}  // namespace
}  // namespace hsa::io
