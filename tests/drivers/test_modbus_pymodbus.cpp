// The modbus plugin against an implementation nobody here wrote: Debian's python3-pymodbus
// serving known register contents (tests/drivers/pymodbus_server.py packs them with Python's
// struct). Reads must give the right SI values for every type and word order; writes are read
// back raw by a second, independent client connection; killing the server must make samples
// stale and count link errors, and its return must bring the link back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <memory>
#include <set>
#include <string>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/modbus_driver_loop.hpp"
#include "tests/drivers/modbus_raw_client.hpp"
#include "tests/drivers/test_modbus_support.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using modbus_test::channel;
using modbus_test::ChildProcess;
using modbus_test::DriverLoop;
using modbus_test::tcp_link;
using ::testing::HasSubstr;
using modbus_test::wait_until;

constexpr Duration cycle_period = DriverLoop::cycle_period;

class PymodbusServer {
 public:
  PymodbusServer() : port_(modbus_test::free_tcp_port()) { start(); }
  void start() {
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{"/usr/bin/python3", HSA_PYMODBUS_SERVER, std::to_string(port_)});
    up_ = wait_until([&] { return modbus_test::tcp_accepts(port_); }, 20s);
  }
  void kill() { process_->kill_now(); }
  [[nodiscard]] bool up() const { return up_; }
  [[nodiscard]] int port() const { return port_; }

 private:
  int port_;
  std::unique_ptr<ChildProcess> process_;
  bool up_ = false;
};


TEST(ModbusPymodbus, ReadsEveryTypeAndWordOrderInSIUnits) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) +
          channel("i16", "analog_input", "input_register", 0, "type = \"int16\"\n") +
          channel("u16", "analog_input", "input_register", 1, "type = \"uint16\"\n") +
          channel("i32_hi", "analog_input", "input_register", 2, "type = \"int32\"\n") +
          channel("i32_lo", "analog_input", "input_register", 4, "type = \"int32\"\nword_order = \"low_first\"\n") +
          channel("f32_hi", "analog_input", "input_register", 6, "type = \"float32\"\n") +
          channel("f32_lo", "encoder_input", "input_register", 8, "type = \"float32\"\nword_order = \"low_first\"\n") +
          channel("scaled", "analog_input", "input_register", 10, "scale = 0.01\noffset = -5.0\n") +
          channel("pressure", "analog_input", "input_register", 11, "type = \"float32\"\nscale = 1e-5\nunit = \"bar\"\n") +
          channel("hr_back", "analog_input", "holding_register", 20, "type = \"uint16\"\n") +
          channel("di0", "digital_input", "discrete_input", 0) +
          channel("di1", "digital_input", "discrete_input", 1) +
          channel("di2", "digital_input", "discrete_input", 2) +
          channel("coil_back", "digital_input", "coil", 5));
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("coil_back").status == SampleStatus::ok &&
                                         rig.slot("i16").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(rig.slot("i16").value, -1234.0);
  EXPECT_EQ(rig.slot("u16").value, 50000.0);
  EXPECT_EQ(rig.slot("i32_hi").value, -100000.0);
  EXPECT_EQ(rig.slot("i32_lo").value, -100000.0);
  EXPECT_EQ(rig.slot("f32_hi").value, 12.5);
  EXPECT_EQ(rig.slot("f32_lo").value, 12.5);
  EXPECT_DOUBLE_EQ(rig.slot("scaled").value, 20.0);
  EXPECT_DOUBLE_EQ(rig.slot("pressure").value, 250.0);
  EXPECT_EQ(rig.slot("hr_back").value, 777.0);
  EXPECT_EQ(rig.slot("di0").value, 1.0);
  EXPECT_EQ(rig.slot("di1").value, 0.0);
  EXPECT_EQ(rig.slot("di2").value, 1.0);
  EXPECT_EQ(rig.slot("coil_back").value, 0.0);
  // Each sample carries the time it was polled, on the cycle's clock: before the read that
  // handed it over, and no older than the plugin's max_age (status ok).
  const ChannelSlot& s = rig.slot("f32_hi");
  EXPECT_EQ(s.status, SampleStatus::ok);
  EXPECT_LE(s.timestamp, rig.now());
  EXPECT_GE(s.timestamp, rig.t - std::chrono::milliseconds(100));
  EXPECT_EQ(rig.slot("link_up").value, 1.0);
  EXPECT_EQ(rig.slot("link_errors").value, 0.0);
  EXPECT_EQ(rig.slot("transaction_errors").value, 0.0);
}

TEST(ModbusPymodbus, WritesLandWhereExpectedAndSafeValuesFrameActivation) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) +
          channel("cmd_i16", "analog_output", "holding_register", 0, "scale = 0.01\nsafe_value = -1.0\n") +
          channel("cmd_u16", "analog_output", "holding_register", 1, "type = \"uint16\"\n") +
          channel("cmd_i32", "analog_output", "holding_register", 2, "type = \"int32\"\n") +
          channel("cmd_f32_lo", "analog_output", "holding_register", 4,
                  "type = \"float32\"\nword_order = \"low_first\"\noffset = 1.0\n") +
          channel("cmd_f32_hi", "analog_output", "holding_register", 10, "type = \"float32\"\n") +
          channel("enable", "digital_output", "coil", 0) +
          channel("pump", "digital_output", "coil", 1, "safe_value = true\n"));
  modbus_test::ModbusRawClient raw(server.port(), std::chrono::seconds(1));
  ASSERT_TRUE(raw.connected());
  const auto regs = [&] { return raw.registers(0, 12); };
  // Inactive: the safe values are on the device (-1.0 at scale 0.01 is -100 = 0xFF9C).
  // Coils and registers go in separate requests: wait for both.
  EXPECT_TRUE(wait_until([&] {
    const auto r = regs();
    return raw.coils(0, 2) == std::vector<std::uint8_t>{0, 1} && !r.empty() && r[0] == 0xFF9C;
  }, 3s)) << "safe values never reached the device before activation";

  ASSERT_TRUE(rig.driver->activate().ok());
  const auto set = [&](const std::string& name, double v) { rig.slot(name).value = v; };
  set("cmd_i16", -2.5);       // raw -250 = 0xFF06
  set("cmd_u16", 65000.0);    // 0xFDE8
  set("cmd_i32", -100000.0);  // 0xFFFE 0x7960
  set("cmd_f32_lo", 13.5);    // raw 12.5 = 0x41480000, low word first
  set("cmd_f32_hi", -2.0);    // 0xC0000000
  set("enable", 1.0);
  set("pump", 0.0);
  const std::vector<std::uint16_t> expected{0xFF06, 0xFDE8, 0xFFFE, 0x7960, 0x0000, 0x4148,
                                            0, 0, 0, 0, 0xC000, 0x0000};
  EXPECT_TRUE(rig.run_until([&] { return regs() == expected; }, 3s)) << "registers never matched";
  EXPECT_EQ(raw.coils(0, 2), (std::vector<std::uint8_t>{1, 0}));

  // Deactivation puts back the safe values before it returns.
  ASSERT_TRUE(rig.driver->deactivate().ok());
  const auto after = regs();
  ASSERT_EQ(after.size(), 12u);
  EXPECT_EQ(after[0], 0xFF9C);
  EXPECT_EQ(after[1], 0);
  EXPECT_EQ(after[2], 0);
  EXPECT_EQ(after[5], 0xBF80);  // safe 0.0 minus offset 1.0 = -1.0f = 0xBF800000, low word first
  EXPECT_EQ(after[4], 0x0000);
  EXPECT_EQ(raw.coils(0, 2), (std::vector<std::uint8_t>{0, 1}));
}

TEST(ModbusPymodbus, ExceptionAnswersAreTransactionErrorsAndTheLinkStaysUp) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + channel("good", "analog_input", "input_register", 1, "type = \"uint16\"\n") +
          channel("missing", "analog_input", "input_register", 200));  // the server has 100 registers
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("transaction_errors").value >= 3; }, 3s));
  EXPECT_EQ(rig.slot("good").status, SampleStatus::ok);
  EXPECT_EQ(rig.slot("good").value, 50000.0);
  EXPECT_EQ(rig.slot("missing").status, SampleStatus::disconnected);  // never read
  EXPECT_EQ(rig.slot("link_up").value, 1.0);
  EXPECT_EQ(rig.slot("link_errors").value, 0.0);
  // The health says which block the device refuses and how: an input that never arrives is not
  // a disconnected device.
  const DriverHealth health = rig.driver->health();
  EXPECT_EQ(health.link, DriverHealth::Link::up);
  EXPECT_THAT(health.last_error, ::testing::HasSubstr(": Modbus exception 2 (Illegal data address) reading input "
                                                      "registers 200..200"));
}

// A device that refuses the outputs (exception 2: the server has 100 holding registers) is
// refused at activation, with the exception and the register block, and the driver stays
// inactive: nothing live is handed to the RT side.
TEST(ModbusPymodbus, ADeviceRefusingTheOutputsIsRefusedAtActivationNamingTheExceptionAndTheBlock) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + channel("ok", "analog_output", "holding_register", 0) +
                 channel("beyond", "analog_output", "holding_register", 150));
  // Inactive, the refused safe values are transaction errors only: the driver stays usable.
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("transaction_errors").value >= 2; }, 3s));
  EXPECT_EQ(rig.driver->state(), DriverState::inactive);
  const Result activated = rig.driver->activate();
  ASSERT_FALSE(activated.ok());
  EXPECT_THAT(activated.message(), ::testing::HasSubstr("write failed: Modbus exception 2 ("));
  EXPECT_THAT(activated.message(), ::testing::HasSubstr("writing holding registers 150..150 of Modbus TCP 127.0.0.1:" +
                                                        std::to_string(server.port())));
  EXPECT_EQ(rig.driver->state(), DriverState::inactive);
  rig.cycle();  // the inputs are still read, and nothing failed
  EXPECT_EQ(rig.driver->state(), DriverState::inactive);
}

// make_safe, from the RT thread: the bus thread writes the safe values from then on, although
// write() keeps publishing the command, and keeps them until the next activation.
TEST(ModbusPymodbus, MakeSafePutsTheSafeValuesOnTheDeviceAndKeepsThemThere) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) +
                 channel("cmd", "analog_output", "holding_register", 0, "scale = 0.01\nsafe_value = -1.0\n") +
                 channel("enable", "digital_output", "coil", 0));
  modbus_test::ModbusRawClient raw(server.port(), std::chrono::seconds(1));
  ASSERT_TRUE(raw.connected());
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.slot("cmd").value = 2.5;  // raw 250
  rig.slot("enable").value = 1.0;
  ASSERT_TRUE(rig.run_until([&] { return raw.registers(0, 1) == std::vector<std::uint16_t>{250} &&
                                         raw.coils(0, 1) == std::vector<std::uint8_t>{1}; }, 3s));

  rig.driver->make_safe();
  // -1.0 at scale 0.01 is raw -100 = 0xFF9C; the enable coil off.
  const auto safe = [&] { return raw.registers(0, 1) == std::vector<std::uint16_t>{0xFF9C} &&
                                 raw.coils(0, 1) == std::vector<std::uint8_t>{0}; };
  ASSERT_TRUE(rig.run_until(safe, 3s)) << "make_safe never reached the device";
  for (int i = 0; i < 20; ++i) {  // many bus polls with write() still sending the command
    rig.cycle();
    std::this_thread::sleep_for(5ms);
    ASSERT_TRUE(safe()) << "the command came back after make_safe, at check " << i;
  }
  // A new activation lets the command through again.
  ASSERT_TRUE(rig.driver->deactivate().ok());
  ASSERT_TRUE(rig.driver->activate().ok());
  EXPECT_TRUE(rig.run_until([&] { return raw.registers(0, 1) == std::vector<std::uint16_t>{250}; }, 3s));
}

// A stalled RT side: once write() stops, the bus thread writes the safe values (and counts it);
// once write() runs again, the command returns.
TEST(ModbusPymodbus, OutputsTimeOutToTheirSafeValuesWhenWriteStops) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  // 0.2 s: far above a loaded test machine's scheduling gaps between two cycles.
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + "output_timeout_s = 0.2\n" +
                 channel("cmd", "analog_output", "holding_register", 0, "safe_value = 7\n"));
  modbus_test::ModbusRawClient raw(server.port(), std::chrono::seconds(1));
  ASSERT_TRUE(raw.connected());
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.slot("cmd").value = 123.0;
  const auto reg = [&] { const auto r = raw.registers(0, 1); return r.empty() ? -1 : int{r[0]}; };
  ASSERT_TRUE(rig.run_until([&] { return reg() == 123; }, 3s));
  rig.cycle();
  EXPECT_EQ(rig.slot("output_timeouts").value, 0.0);

  // No more read() or write(): the daemon's RT thread has stopped.
  ASSERT_TRUE(wait_until([&] { return reg() == 7; }, 5s)) << "the stale command stayed on the device";
  rig.cycle();  // the RT side is back
  EXPECT_GE(rig.slot("output_timeouts").value, 1.0);
  EXPECT_TRUE(rig.run_until([&] { return reg() == 123; }, 3s)) << "the command did not return";
}

// The heartbeat channel counts write() calls: it changes while the RT side writes and stands
// still when it stops, even though the bus thread keeps polling (a long output_timeout_s here, so
// the stop shows as a frozen counter, not as the safe value).
TEST(ModbusPymodbus, TheHeartbeatCountsWritesAndStopsWithThem) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + "output_timeout_s = 30\n" +
                 channel("cmd", "analog_output", "holding_register", 0) +
                 channel("beat", "analog_output", "holding_register", 1, "type = \"uint16\"\nheartbeat = true\n"));
  modbus_test::ModbusRawClient raw(server.port(), std::chrono::seconds(1));
  ASSERT_TRUE(raw.connected());
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.slot("beat").value = 5000.0;  // ignored: the channel carries the counter
  std::set<int> seen;
  const auto beat = [&] { const auto r = raw.registers(1, 1); return r.empty() ? -1 : int{r[0]}; };
  ASSERT_TRUE(rig.run_until([&] { seen.insert(beat()); return seen.size() >= 4; }, 5s, [] {
    std::this_thread::sleep_for(1ms);
  })) << "the heartbeat did not change while write() ran";
  EXPECT_EQ(seen.count(5000), 0u);
  // write() stops; the bus keeps polling (link up, inputs fresh), the counter stands still.
  std::this_thread::sleep_for(50ms);  // let the last published value reach the device
  const int frozen = beat();
  for (int i = 0; i < 10; ++i) {
    std::this_thread::sleep_for(10ms);  // several bus polls (2 ms each)
    EXPECT_EQ(beat(), frozen);
  }
  EXPECT_EQ(rig.driver->state(), DriverState::active);
}

// When the outputs go safe (an output timeout, then make_safe), a heartbeat stops at the last
// count the RT side published instead of taking its safe value: a device watching it for changes
// would take a jump back to 0 for one more beat.
TEST(ModbusPymodbus, AHeartbeatStopsAtItsLastCountWhenTheOutputsGoSafe) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + "output_timeout_s = 0.2\n" +
                 channel("cmd", "analog_output", "holding_register", 0, "safe_value = 7\n") +
                 channel("beat", "analog_output", "holding_register", 1, "type = \"uint16\"\nheartbeat = true\n"));
  modbus_test::ModbusRawClient raw(server.port(), std::chrono::seconds(1));
  ASSERT_TRUE(raw.connected());
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.slot("cmd").value = 123.0;
  const auto reg = [&](int address) { const auto r = raw.registers(address, 1); return r.empty() ? -1 : int{r[0]}; };
  // Enough writes, seen by a live bus thread, that the count is far from the safe value 0.
  ASSERT_TRUE(rig.run_until([&] { return reg(0) == 123 && reg(1) >= 50; }, 3s));
  std::this_thread::sleep_for(50ms);  // let the last published count reach the device
  const int last = reg(1);

  // write() stops: the output timeout puts the command to 7, the heartbeat stays at its count.
  ASSERT_TRUE(wait_until([&] { return reg(0) == 7; }, 5s)) << "the output timeout never came";
  EXPECT_EQ(reg(1), last) << "the heartbeat left its last count when the outputs went safe";

  // make_safe: the same.
  rig.cycle();
  ASSERT_TRUE(rig.run_until([&] { return reg(0) == 123; }, 3s));
  const int before_safe = reg(1);
  rig.driver->make_safe();
  ASSERT_TRUE(wait_until([&] { return reg(0) == 7; }, 3s)) << "make_safe never reached the device";
  EXPECT_GE(reg(1), before_safe);
  EXPECT_NE(reg(1), 0) << "the heartbeat took its safe value";
}

TEST(ModbusPymodbus, ServerDeathMakesSamplesStaleAndItsReturnReconnects) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + channel("x", "analog_input", "input_register", 6, "type = \"float32\"\n"));
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("x").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(rig.driver->health().link, DriverHealth::Link::up);
  EXPECT_EQ(rig.driver->health().last_error, "");

  server.kill();
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("x").status == SampleStatus::stale; }, 3s));
  EXPECT_EQ(rig.slot("x").value, 12.5);  // the last value, handed over marked stale
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("link_errors").value >= 2; }, 3s));
  EXPECT_EQ(rig.slot("link_up").value, 0.0);
  EXPECT_EQ(rig.slot("transaction_errors").value, 0.0);
  // The health the daemon's status shows says the same, with the link and the cause.
  const DriverHealth down = rig.driver->health();
  EXPECT_EQ(down.link, DriverHealth::Link::down);
  EXPECT_THAT(down.last_error, HasSubstr("Modbus TCP 127.0.0.1:" + std::to_string(server.port()) + ": "));
  EXPECT_THAT(down.last_error, HasSubstr("Connection refused"));
  ASSERT_EQ(down.counters.size(), 4u);
  EXPECT_EQ(down.counters[0].first, "link_errors");
  EXPECT_GE(down.counters[0].second, 2u);
  // Refused and reset, never timed out: a dead device is not a silent one.
  EXPECT_EQ(down.counters[1], (std::pair<std::string, std::uint64_t>{"timeouts", 0}));
  EXPECT_EQ(down.counters[2], (std::pair<std::string, std::uint64_t>{"transaction_errors", 0}));
  // The RT cycle kept running without waiting on the dead bus: the age grows with it, and the
  // repeated sample keeps its timestamp, so nobody takes it for a fresh one.
  const Timestamp stamp = rig.slot("x").timestamp;
  constexpr int kCycles = 200;
  for (int i = 0; i < kCycles; ++i) {
    rig.cycle();
    std::this_thread::sleep_for(1ms);  // once a millisecond, as hsad's loop
  }
  EXPECT_EQ(rig.slot("x").timestamp, stamp);
  EXPECT_GE(rig.t - rig.slot("x").timestamp, kCycles * cycle_period);

  server.start();
  ASSERT_TRUE(server.up()) << "pymodbus server did not come back";
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("x").status == SampleStatus::ok; }, 10s));
  EXPECT_EQ(rig.slot("link_up").value, 1.0);
  EXPECT_EQ(rig.slot("x").value, 12.5);
}

// The host holds the RT thread between the cycle's start and its read() (a VM whose CPU was
// taken), while the bus thread polls on. The sample read then was polled during the hold-up and
// is stamped when it was polled, after the cycle's start. Stamped by its age at the late read
// (t - age), it would land before the cycle's start, and the interval from the previous sample
// would shrink by the hold-up: in hsad a rod moving within its speed bound read as an encoder jump.
TEST(ModbusPymodbus, ACycleHeldUpBeforeItsReadStampsTheSampleWhenItWasPolled) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + channel("x", "analog_input", "input_register", 6, "type = \"float32\"\n"));
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("x").status == SampleStatus::ok; }, 3s));
  for (int i = 0; i < 20; ++i) {  // a steady run first, as hsad's loop
    rig.cycle();
    std::this_thread::sleep_for(1ms);
  }
  const Timestamp before = rig.slot("x").timestamp;

  const Timestamp t = rig.now();
  std::this_thread::sleep_for(60ms);  // the hold-up: 30 poll periods
  ASSERT_EQ(rig.driver->read(t, cycle_period), IoStatus::ok);
  const ChannelSlot& held = rig.slot("x");
  EXPECT_EQ(held.status, SampleStatus::ok);
  EXPECT_GT(held.timestamp, t) << "stamped before the cycle began, " << (t - held.timestamp).count() << " ns";
  EXPECT_LE(held.timestamp, rig.now());
  EXPECT_GT(held.timestamp - before, t - before);  // the interval kept the hold-up
}

TEST(ModbusPymodbus, ReadAndWriteAllocateNothingWhileTheBusRuns) {
  PymodbusServer server;
  ASSERT_TRUE(server.up()) << "pymodbus server did not come up";
  DriverLoop rig(tcp_link(server.port(), 0.2, 0.4) + channel("x", "analog_input", "input_register", 6, "type = \"float32\"\n") +
          channel("d", "digital_input", "discrete_input", 0) +
          channel("u", "analog_output", "holding_register", 0, "type = \"float32\"\n") +
          channel("en", "digital_output", "coil", 0));
  ASSERT_TRUE(rig.driver->activate().ok());
  ASSERT_TRUE(rig.run_until([&] { return rig.slot("x").status == SampleStatus::ok; }, 3s));
  const long before = hsa::test::thread_allocations();
  long fresh = 0;
  Timestamp last{};
  const auto deadline = modbus_test::Clock::now() + 20s;
  for (int i = 0; (i < 300 || fresh <= 10) && modbus_test::Clock::now() < deadline; ++i) {
    rig.slot("u").value = 0.001 * (i % 1000);
    rig.cycle();
    if (rig.slot("x").timestamp != last) ++fresh;
    last = rig.slot("x").timestamp;
    std::this_thread::sleep_for(1ms);
  }
  rig.driver->make_safe();  // the RT thread's make_safe allocates nothing either
  rig.cycle();
  EXPECT_EQ(hsa::test::thread_allocations() - before, 0);
  EXPECT_GT(fresh, 10);  // new samples did arrive meanwhile: the exchange was exercised
}

// RTU: the same pymodbus peer on one end of a pseudo-terminal pair that socat joins, the plugin
// on the other, 19200 8N1. A first driver instance writes a holding register through its safe
// value (written while inactive); a second one reads it back along with the typed inputs.
TEST(ModbusRtu, ReadsAndWritesOverASerialLine) {
  if (std::string(HSA_SOCAT).empty()) GTEST_SKIP() << "socat is not installed";
  char dir_template[] = "/tmp/hsa-modbus-rtu-XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  ChildProcess socat({HSA_SOCAT, "pty,raw,echo=0,link=" + dir + "/master",
                      "pty,raw,echo=0,link=" + dir + "/device"});
  ASSERT_TRUE(wait_until([&] { return access((dir + "/device").c_str(), F_OK) == 0 &&
                                      access((dir + "/master").c_str(), F_OK) == 0; }, 5s));
  ChildProcess peer({"/usr/bin/python3", HSA_PYMODBUS_SERVER, "rtu", dir + "/device"});
  const std::string link = "transport = \"rtu\"\ndevice = \"" + dir + "/master\"\nbaud = 19200\n"
                           "parity = \"none\"\npoll_period_s = 0.01\nresponse_timeout_s = 0.2\n";
  {
    DriverLoop writer(link + channel("cmd", "analog_output", "holding_register", 3,
                              "type = \"float32\"\nword_order = \"low_first\"\nsafe_value = 42.5\n") +
               channel("i16", "analog_input", "input_register", 0));
    // Up once the python peer answers (it starts in the background).
    ASSERT_TRUE(writer.run_until([&] { return writer.slot("i16").status == SampleStatus::ok; }, 15s));
    EXPECT_EQ(writer.slot("i16").value, -1234.0);
  }
  DriverLoop reader(link + channel("back", "analog_input", "holding_register", 3,
                            "type = \"float32\"\nword_order = \"low_first\"\n") +
             channel("i32_lo", "analog_input", "input_register", 4, "type = \"int32\"\nword_order = \"low_first\"\n") +
             channel("di0", "digital_input", "discrete_input", 0));
  ASSERT_TRUE(reader.run_until([&] { return reader.slot("back").status == SampleStatus::ok &&
                                            reader.slot("di0").status == SampleStatus::ok; }, 5s));
  EXPECT_EQ(reader.slot("back").value, 42.5);
  EXPECT_EQ(reader.slot("i32_lo").value, -100000.0);
  EXPECT_EQ(reader.slot("di0").value, 1.0);
  EXPECT_EQ(reader.slot("link_errors").value, 0.0);
  peer.kill_now();
  socat.kill_now();
  std::filesystem::remove_all(dir);
}

// A peer that accepts the connection and never answers: every transaction times out. The RT
// cycle must not notice anything but the sample status. The cycles are timed while the bus thread
// sits in those timeouts; a cycle that waited on the bus even once would take at least the
// response timeout (1 s here), which is what each cycle is held under. No other wall-clock bound
// is asserted: a loaded machine may stretch a cycle, never to a second.
TEST(ModbusTimeout, ASilentPeerGivesLinkErrorsAndNeverBlocksTheCycle) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(listen(fd, 16), 0);  // the kernel completes handshakes; nobody ever reads
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const int port = ntohs(addr.sin_port);

  constexpr auto response_timeout = 1s;
  DriverLoop rig(tcp_link(port, 1.0, 0.4) + channel("x", "analog_input", "input_register", 0));
  Duration slowest{};
  const auto timed_cycle = [&] {
    const auto start = modbus_test::Clock::now();
    rig.cycle();
    slowest = std::max(slowest, std::chrono::duration_cast<Duration>(modbus_test::Clock::now() - start));
  };
  // Every cycle from the start is timed, through at least two timed-out transactions.
  const bool counted = wait_until([&] { return rig.slot("link_errors").value >= 2; }, 20s, timed_cycle);
  close(fd);
  ASSERT_TRUE(counted);
  EXPECT_EQ(rig.slot("x").status, SampleStatus::disconnected);
  EXPECT_EQ(rig.slot("transaction_errors").value, 0.0);
  EXPECT_LT(slowest, response_timeout);
}

}  // namespace
}  // namespace hsa::io
