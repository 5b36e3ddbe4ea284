// hsa-simdev, the simulated rig served over Modbus TCP: answered correctly by mbpoll (a Modbus
// master nobody here wrote), and driven end to end by the modbus plugin: a command through the
// plugin moves the simulated rod, and a position loop closed through both reaches its setpoint.
// And its communication watchdog (tools/hsa_simdev/register_map.hpp): seen by a second libmodbus
// client that only reads while the first, the master, writes and then stops; fed by the master
// alone, whatever a second client writes; its e-stop, which cuts the valve's power; and the test
// hook that makes it refuse the master's valve command.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <modbus/modbus.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <memory>
#include <regex>
#include <string>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/modbus_driver_loop.hpp"
#include "tests/drivers/modbus_raw_client.hpp"
#include "tests/drivers/test_modbus_support.hpp"
#include "tools/hsa_simdev/register_map.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using modbus_test::ChildProcess;
using modbus_test::Clock;
using modbus_test::DriverLoop;
using modbus_test::wait_until;
namespace map = hsa::simdev;

// hsa-simdev on a free port, for at most 60 s whatever happens to the test.
class Simdev {
 public:
  explicit Simdev(const std::vector<std::string>& extra = {}) : process_(args(extra)) {
    const auto line = process_.read_line(10s);
    std::smatch m;
    if (line && std::regex_search(*line, m, std::regex("listening on 127\\.0\\.0\\.1:([0-9]+)"))) {
      port_ = std::stoi(m[1]);
    }
  }
  [[nodiscard]] int port() const { return port_; }

 private:
  static std::vector<std::string> args(const std::vector<std::string>& extra) {
    std::vector<std::string> a{HSA_SIMDEV, "--port", "0", "--duration", "60"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  ChildProcess process_;
  int port_ = 0;
};

// mbpoll's output and exit status.
struct Poll {
  int status = -1;
  std::string output;
};

// mbpoll [options] host [values to write]
Poll mbpoll(int port, const std::vector<std::string>& args, const std::vector<std::string>& write = {}) {
  std::vector<std::string> argv{HSA_MBPOLL, "-m", "tcp", "-a", "1", "-0", "-1", "-o", "2"};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.insert(argv.end(), {"-p", std::to_string(port), "127.0.0.1"});
  argv.insert(argv.end(), write.begin(), write.end());
  ChildProcess p(argv);
  Poll result;
  result.output = p.read_all(10s);
  result.status = p.wait_exit(5s).value_or(-1);
  return result;
}

// The value mbpoll printed for `reference` ("[2]: \t1.1082e+06"), or NaN.
double value_at(const std::string& output, int reference) {
  std::smatch m;
  const std::regex line("\\[" + std::to_string(reference) + "\\]:\\s+(-?[0-9.eE+-]+)");
  return std::regex_search(output, m, line) ? std::stod(m[1]) : std::nan("");
}

TEST(ModbusSimdev, AnswersMbpoll) {
  if (std::string(HSA_MBPOLL).empty()) GTEST_SKIP() << "mbpoll is not installed";
  Simdev simdev;
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";

  // Float32 input registers, high word first (-B): position, pressures A and B.
  const Poll floats = mbpoll(simdev.port(), {"-B", "-t", "3:float", "-r", std::to_string(map::input_register::position_m), "-c", "3"});
  ASSERT_EQ(floats.status, 0) << floats.output;
  EXPECT_NEAR(value_at(floats.output, 0), 0.150, 1e-3) << floats.output;  // the initial position
  for (const int ref : {2, 4}) {
    const double p = value_at(floats.output, ref);
    EXPECT_GT(p, 1e5) << floats.output;  // a rod held against gravity by pressurised chambers
    EXPECT_LT(p, 2.6e6) << floats.output;  // never above the relief setting of 25 bar
  }

  // The same position as a scaled int32 (1 µm per count).
  const Poll ints = mbpoll(simdev.port(), {"-B", "-t", "3:int", "-r", std::to_string(map::input_register::position_um_i32)});
  ASSERT_EQ(ints.status, 0) << ints.output;
  EXPECT_NEAR(value_at(ints.output, 20), 150000, 1000) << ints.output;

  // Writes: press the e-stop button through its coil; the e-stop loop input opens.
  const Poll closed = mbpoll(simdev.port(), {"-t", "1", "-r", "0"});
  ASSERT_EQ(closed.status, 0) << closed.output;
  EXPECT_EQ(value_at(closed.output, 0), 1.0) << closed.output;
  ASSERT_EQ(mbpoll(simdev.port(), {"-t", "0", "-r", std::to_string(map::coil::estop_button)}, {"1"}).status, 0);
  double loop = 1.0;
  wait_until([&] {
    loop = value_at(mbpoll(simdev.port(), {"-t", "1", "-r", "0"}).output, 0);
    return loop == 0.0;
  }, 3s);
  EXPECT_EQ(loop, 0.0);
}

std::string simdev_settings(int port) {
  return "transport = \"tcp\"\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) + R"(
poll_period_s = 0.002
response_timeout_s = 0.1
max_age_s = 0.05
[[channels]]
name = "encoder"
kind = "encoder_input"
table = "input_register"
address = 0
type = "float32"
unit = "m"
[[channels]]
name = "pressure_a"
kind = "analog_input"
table = "input_register"
address = 22
type = "int32"
unit = "Pa"
[[channels]]
name = "opening_cmd"
kind = "analog_output"
table = "holding_register"
address = 0
type = "float32"
[[channels]]
name = "valve_enable"
kind = "digital_output"
table = "coil"
address = 0
[[channels]]
name = "estop"
kind = "digital_input"
table = "discrete_input"
address = 0
)";
}

TEST(ModbusSimdev, PluginCommandMovesTheRodAndClosesAPositionLoop) {
  Simdev simdev;
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  DriverLoop loop(simdev_settings(simdev.port()));

  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(loop.slot("estop").value, 1.0);  // loop closed: not pressed
  EXPECT_GT(loop.slot("pressure_a").value, 1e5);
  const double start = loop.slot("encoder").value;
  EXPECT_NEAR(start, 0.150, 1e-3);

  // Open loop: a positive opening extends the rod, a negative one retracts it.
  ASSERT_TRUE(loop.driver->activate().ok());
  loop.slot("valve_enable").value = 1.0;
  loop.slot("opening_cmd").value = 0.2;
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").value > start + 0.005; }, 5s))
      << "rod at " << loop.slot("encoder").value;
  loop.slot("opening_cmd").value = -0.2;
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").value < start; }, 5s)) << "rod at " << loop.slot("encoder").value;

  // Closed loop through the bus: proportional position control to 20 mm above the start.
  const double setpoint = start + 0.020;
  const auto settled = [&] {
    const double x = loop.slot("encoder").value;
    loop.slot("opening_cmd").value = std::clamp(25.0 * (setpoint - x), -0.3, 0.3);
    return std::abs(setpoint - x) < 1e-3 && loop.slot("encoder").status == SampleStatus::ok;
  };
  ASSERT_TRUE(loop.run_until(settled, 8s)) << "rod at " << loop.slot("encoder").value << ", setpoint " << setpoint;
  // And it stays there.
  loop.run_until([&] { (void)settled(); return false; }, 500ms);
  EXPECT_NEAR(loop.slot("encoder").value, setpoint, 2e-3);

  // Deactivation: amplifier off, command 0, confirmed on the device before it returns.
  ASSERT_TRUE(loop.driver->deactivate().ok());
  EXPECT_EQ(loop.slot("link_errors").value, 0.0);
  EXPECT_EQ(loop.slot("transaction_errors").value, 0.0);
}

// One libmodbus TCP client connection to hsa-simdev; every call bounded by a 1 s response timeout.
class Client : public modbus_test::ModbusRawClient {
 public:
  explicit Client(int port) : ModbusRawClient(port, std::chrono::seconds(1)), ctx_(get()) {}

  // The master's write: the valve command (float32, high word first) and the enable coil.
  bool write_valve(float command, bool enable) {
    return write_command(command) && modbus_write_bit(ctx_, map::coil::valve_enable, enable ? 1 : 0) == 1;
  }
  // The valve command alone; on failure errno holds libmodbus's reason (an exception: EMBX...).
  bool write_command(float command) {
    const auto bits = std::bit_cast<std::uint32_t>(command);
    std::uint16_t regs[2] = {static_cast<std::uint16_t>(bits >> 16), static_cast<std::uint16_t>(bits & 0xFFFFu)};
    return modbus_write_registers(ctx_, map::holding_register::valve_command, 2, regs) == 2;
  }
  bool refuse_command(bool refuse) {
    return modbus_write_bit(ctx_, map::coil::refuse_valve_command, refuse ? 1 : 0) == 1;
  }
  bool write_enable(bool enable) { return modbus_write_bit(ctx_, map::coil::valve_enable, enable ? 1 : 0) == 1; }
  bool write_heartbeat(std::uint16_t value) {
    return modbus_write_register(ctx_, map::holding_register::master_heartbeat, value) == 1;
  }
  bool press_estop(bool pressed) { return modbus_write_bit(ctx_, map::coil::estop_button, pressed ? 1 : 0) == 1; }
  // An input register, or -1 when the read failed.
  int input_register(int address) {
    std::uint16_t v = 0;
    return modbus_read_input_registers(ctx_, address, 1, &v) == 1 ? v : -1;
  }
  // The rod position in µm (int32, high word first), or NaN when the read failed.
  double position_um() {
    std::uint16_t r[2];
    if (modbus_read_input_registers(ctx_, map::input_register::position_um_i32, 2, r) != 2) return NAN;
    return static_cast<double>(static_cast<std::int32_t>(static_cast<std::uint32_t>(r[0]) << 16 | r[1]));
  }

  // What a monitor reads (function codes 01, 02, 03, 04 only): the watchdog state first, so
  // that when it says tripped, the valve registers read after it must already be safe.
  struct Seen {
    bool ok = false;
    float command = NAN;
    bool enable = false;
    int tripped = -1;       // input register 40
    int trips = -1;         // input register 41
    int watchdog_ms = -1;   // input register 42
    int tripped_bit = -1;   // discrete input 1
  };
  Seen read() {
    Seen s;
    std::uint16_t regs[2];
    std::uint8_t enable = 0;
    std::uint16_t wd[3];
    std::uint8_t bit = 0;
    s.ok = modbus_read_input_registers(ctx_, map::input_register::watchdog_tripped, 3, wd) == 3 &&
           modbus_read_input_bits(ctx_, map::discrete_input::watchdog_tripped, 1, &bit) == 1 &&
           modbus_read_registers(ctx_, map::holding_register::valve_command, 2, regs) == 2 &&
           modbus_read_bits(ctx_, map::coil::valve_enable, 1, &enable) == 1;
    if (!s.ok) return s;
    s.command = std::bit_cast<float>(static_cast<std::uint32_t>(regs[0]) << 16 | regs[1]);  // high word first
    s.enable = enable != 0;
    s.tripped = wd[0];
    s.trips = wd[1];
    s.watchdog_ms = wd[2];
    s.tripped_bit = bit;
    return s;
  }

 private:
  modbus_t* ctx_;  // the base's context, under the name the calls above use
};

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// The watchdog trips only after watchdog_ms without a write, whatever the machine's load: while
// the master writes every few ms it holds its command, unless the test itself stalled longer than
// the watchdog time between two writes (then a trip is legitimate, and that is checked instead).
// After the last write the valve goes safe, enable off, latched: never sooner than watchdog_ms
// after that write began (the device's clock and ours are both CLOCK_MONOTONIC), and within a
// generous bound. Writes while latched are held at the safe values; writing the enable off clears
// the latch, and then the master commands the valve again.
TEST(ModbusSimdevWatchdog, TripsOnlyWhenWritesStopLatchesAndTheMasterClearsIt) {
  Simdev simdev;  // the default watchdog
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client monitor(simdev.port());
  ASSERT_TRUE(master.connected());
  ASSERT_TRUE(monitor.connected());

  const Client::Seen initial = monitor.read();
  ASSERT_TRUE(initial.ok);
  const int w = initial.watchdog_ms;
  EXPECT_GT(w, 0) << "the watchdog is on by default";
  EXPECT_LE(w, 100) << "the default watchdog time is at most 100 ms";
  EXPECT_EQ(initial.tripped, 0);
  EXPECT_EQ(initial.trips, 0);

  // The monitor alone, reading for 3 watchdog periods before any write: reads neither arm nor
  // feed it, and there is nothing to trip.
  ASSERT_FALSE(wait_until([&] { return monitor.read().tripped != 0; }, std::chrono::milliseconds(3 * w)));

  // Writes every 2 ms for 5 watchdog periods. The device feeds its watchdog somewhere inside each
  // write call, so the longest time it can have gone unfed is bounded by the longest span from the
  // start of one write to the end of the next.
  Clock::time_point last_start = Clock::now();
  ASSERT_TRUE(master.write_valve(0.2f, true));
  double longest_gap_ms = 0.0;
  int tripped_while_writing = 0;
  const auto writing_until = Clock::now() + std::chrono::milliseconds(5 * w);
  while (Clock::now() < writing_until) {
    std::this_thread::sleep_for(2ms);
    const auto start = Clock::now();
    ASSERT_TRUE(master.write_valve(0.2f, true));
    longest_gap_ms = std::max(longest_gap_ms, ms_between(last_start, Clock::now()));
    last_start = start;
    const Client::Seen seen = monitor.read();
    ASSERT_TRUE(seen.ok);
    tripped_while_writing = std::max(tripped_while_writing, seen.tripped);
  }
  if (longest_gap_ms < w) {
    EXPECT_EQ(tripped_while_writing, 0) << "tripped although no write was ever more than " << longest_gap_ms
                                        << " ms apart (watchdog " << w << " ms)";
    const Client::Seen held = monitor.read();
    EXPECT_FLOAT_EQ(held.command, 0.2f);
    EXPECT_TRUE(held.enable);
  } else {
    std::printf("note: this test stalled %.1f ms between two writes (watchdog %d ms); no-trip check skipped\n",
                longest_gap_ms, w);
  }

  // The master falls silent: the last write began at last_start.
  const Client::Seen before = monitor.read();
  Client::Seen seen;
  ASSERT_TRUE(wait_until([&] {
    seen = monitor.read();
    return seen.ok && seen.tripped == 1;
  }, 5s)) << "the watchdog never tripped";
  const double trip_ms = ms_between(last_start, Clock::now());
  std::printf("watchdog %d ms: the first read showing the trip ended %.1f ms after the last write began\n", w,
              trip_ms);
  EXPECT_GE(trip_ms, w) << "tripped early";
  // Generous on purpose: the device checks every 1 ms (--period-s), so on an idle machine this is
  // w + ~1 ms; a full second more is what it takes for a loaded 2-core machine to break it.
  EXPECT_LE(trip_ms, w + 1000.0);
  EXPECT_EQ(seen.trips, before.trips + 1);
  EXPECT_EQ(seen.tripped_bit, 1);
  EXPECT_FLOAT_EQ(seen.command, 0.0f) << "the valve's safe command";
  EXPECT_FALSE(seen.enable);

  // Latched: writes are held at the safe values.
  ASSERT_TRUE(master.write_valve(0.3f, true));
  seen = monitor.read();
  EXPECT_EQ(seen.tripped, 1);
  EXPECT_FLOAT_EQ(seen.command, 0.0f);
  EXPECT_FALSE(seen.enable);

  // The master clears it by writing the enable off. Checked only when the check ran within the
  // watchdog time of the clearing write (else the watchdog may rightly have tripped again);
  // bounded retries.
  bool cleared = false;
  for (int attempt = 0; attempt < 5 && !cleared; ++attempt) {
    const auto start = Clock::now();
    ASSERT_TRUE(master.write_enable(false));
    ASSERT_TRUE(master.write_valve(0.2f, true));
    seen = monitor.read();
    if (ms_between(start, Clock::now()) >= w) continue;
    cleared = true;
    EXPECT_EQ(seen.tripped, 0);
    EXPECT_EQ(seen.tripped_bit, 0);
    EXPECT_FLOAT_EQ(seen.command, 0.2f) << "the master commands the valve again";
    EXPECT_TRUE(seen.enable);
  }
  EXPECT_TRUE(cleared) << "five attempts to clear the latch each took longer than the watchdog time";
  EXPECT_GE(seen.trips, 1);

  // The enable written on while latched does not clear it: only an off does.
  ASSERT_TRUE(wait_until([&] { return monitor.read().tripped == 1; }, 5s));
  ASSERT_TRUE(master.write_valve(0.2f, true));
  EXPECT_EQ(monitor.read().tripped, 1);
}

TEST(ModbusSimdevWatchdog, OffKeepsTheLastCommand) {
  Simdev simdev({"--watchdog-ms", "0"});
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client monitor(simdev.port());
  ASSERT_TRUE(master.connected());
  ASSERT_TRUE(monitor.connected());
  ASSERT_TRUE(master.write_valve(0.2f, true));
  // Three times the default watchdog time (100 ms) with no write.
  std::this_thread::sleep_for(300ms);
  const Client::Seen seen = monitor.read();
  ASSERT_TRUE(seen.ok);
  EXPECT_EQ(seen.watchdog_ms, 0);
  EXPECT_EQ(seen.tripped, 0);
  EXPECT_EQ(seen.trips, 0);
  EXPECT_FLOAT_EQ(seen.command, 0.2f);
  EXPECT_TRUE(seen.enable);
}

TEST(ModbusSimdevMaster, AnotherClientsWritesNeitherFeedTheWatchdogNorClearItsLatch) {
  Simdev simdev;  // the default watchdog
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client monitor(simdev.port());  // writes what a monitor may write, and tries what it may not
  Client observer(simdev.port());  // only reads
  ASSERT_TRUE(master.connected() && monitor.connected() && observer.connected());
  const int w = observer.read().watchdog_ms;
  ASSERT_GT(w, 0);

  // The first connection to write an output owns them; the monitor's output writes are refused,
  // counted, and change nothing.
  ASSERT_TRUE(master.write_valve(0.2f, true));
  EXPECT_TRUE(monitor.write_heartbeat(7)) << "a monitor may write the heartbeat register";
  EXPECT_FALSE(monitor.write_enable(false)) << "the enable is the master's";
  EXPECT_FALSE(monitor.write_valve(-0.5f, true)) << "the valve command is the master's";
  EXPECT_GE(observer.input_register(map::input_register::foreign_writes), 2);
  Client::Seen seen = observer.read();
  EXPECT_FLOAT_EQ(seen.command, 0.2f);
  EXPECT_TRUE(seen.enable);

  // The master falls silent while the monitor writes every 20 ms: the heartbeat (accepted) and
  // the enable (refused). The device must go safe within the watchdog time of the master's last
  // write, as if nobody wrote at all.
  const auto last_master_write = Clock::now();
  std::uint16_t beat = 8;
  bool tripped = false;
  const auto give_up = Clock::now() + 5s;
  while (!tripped && Clock::now() < give_up) {
    EXPECT_TRUE(monitor.write_heartbeat(beat++));
    (void)monitor.write_enable(true);
    seen = observer.read();
    tripped = seen.ok && seen.tripped == 1;
    if (!tripped) std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(tripped) << "a monitor's writes kept a silent master's valve alive for 5 s";
  const double trip_ms = ms_between(last_master_write, Clock::now());
  std::printf("master silent, monitor writing every 20 ms: valve safe at the device %.1f ms after the master's "
              "last write (watchdog %d ms)\n", trip_ms, w);
  EXPECT_GE(trip_ms, w);
  EXPECT_LE(trip_ms, w + 1000.0);  // the same scheduling slack as the master-only test above
  EXPECT_FLOAT_EQ(seen.command, 0.0f);
  EXPECT_FALSE(seen.enable);

  // Only the master's enable-off clears the latch.
  EXPECT_FALSE(monitor.write_enable(false));
  EXPECT_EQ(observer.read().tripped, 1) << "another client's enable-off cleared the latch";
  ASSERT_TRUE(master.write_enable(false));
  EXPECT_EQ(observer.read().tripped, 0);
}

TEST(ModbusSimdevMaster, TheNextWriterIsTheMasterOnceTheMasterHasGone) {
  Simdev simdev;
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client observer(simdev.port());
  {
    Client first(simdev.port());
    ASSERT_TRUE(first.write_valve(0.1f, true));
  }  // closed: a master that went away (hsad restarted)
  Client second(simdev.port());
  bool taken = false;
  for (int attempt = 0; attempt < 50 && !taken; ++attempt) {  // until the device has seen the close
    taken = second.write_enable(false);
    if (!taken) std::this_thread::sleep_for(20ms);
  }
  EXPECT_TRUE(taken) << "a new master could not take the outputs of one that disconnected";
  EXPECT_FALSE(observer.read().enable);
}

// The test hook of coil 9: written by a connection that is not the master (and not refused), it
// makes the device refuse the master's valve command with exception 03, as the modbus plugin will
// report it, while the master can still switch the enable off; writing it 0 ends the refusal.
TEST(ModbusSimdevMaster, Coil9RefusesTheMastersValveCommandWithException3UntilCleared) {
  Simdev simdev;  // the default watchdog: a refused write must not feed it, the enable's must
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client control(simdev.port());  // the test's switch
  ASSERT_TRUE(master.connected() && control.connected());
  ASSERT_TRUE(master.write_valve(0.2f, true));

  ASSERT_TRUE(control.refuse_command(true)) << "the control write itself was refused";
  errno = 0;
  EXPECT_FALSE(master.write_command(-0.3f));
  EXPECT_EQ(errno, EMBXILVAL) << modbus_strerror(errno);
  EXPECT_EQ(control.input_register(map::input_register::refused_command_writes), 1);
  // Another connection's command write is still the master's to make: exception 01, not 03, and
  // not counted as a refusal of the master's.
  errno = 0;
  EXPECT_FALSE(control.write_command(-0.3f));
  EXPECT_EQ(errno, EMBXILFUN) << modbus_strerror(errno);
  EXPECT_EQ(control.input_register(map::input_register::refused_command_writes), 1);
  // The enable is still taken: the master can make the valve safe.
  EXPECT_TRUE(master.write_enable(false));
  Client::Seen seen = control.read();
  ASSERT_TRUE(seen.ok);
  EXPECT_FLOAT_EQ(seen.command, 0.2f) << "a refused write changed the command";
  EXPECT_FALSE(seen.enable);
  EXPECT_EQ(seen.tripped, 0);

  ASSERT_TRUE(control.refuse_command(false));
  EXPECT_TRUE(master.write_valve(-0.3f, true)) << modbus_strerror(errno);
  seen = control.read();
  EXPECT_FLOAT_EQ(seen.command, -0.3f);
  EXPECT_TRUE(seen.enable);
  EXPECT_EQ(control.input_register(map::input_register::refused_command_writes), 1);
}

// Writes the valve command and enable every 5 ms for `how_long`, as a master's bus cycle does,
// and returns the rod's travel over that time in µm.
double travel_while_driving(Client& master, float opening, std::chrono::milliseconds how_long) {
  const double start = master.position_um();
  const auto until = Clock::now() + how_long;
  while (Clock::now() < until) {
    EXPECT_TRUE(master.write_valve(opening, true));
    std::this_thread::sleep_for(5ms);
  }
  return master.position_um() - start;
}

TEST(ModbusSimdevEstop, CutsTheValvePowerUntilReleasedAndTheMasterResets) {
  Simdev simdev({"--initial-position-m", "0.1"});
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client panel(simdev.port());  // the e-stop button's wiring
  ASSERT_TRUE(master.connected() && panel.connected());
  constexpr float kOpening = 0.05f;

  const double moving = travel_while_driving(master, kOpening, 200ms);
  ASSERT_GT(moving, 1000.0) << "the rod did not move with the valve open and powered";

  ASSERT_TRUE(panel.press_estop(true));
  (void)travel_while_driving(master, kOpening, 30ms);  // the valve comes to rest
  const double pressed = travel_while_driving(master, kOpening, 200ms);
  std::printf("rod travel in 200 ms with the valve commanded open %.2f: %.0f µm powered, %.0f µm with the "
              "e-stop pressed\n", kOpening, moving, pressed);
  EXPECT_LT(std::abs(pressed), 0.02 * moving) << "the rod kept moving with the e-stop pressed";
  EXPECT_EQ(panel.input_register(map::input_register::valve_power_cut), 1);

  // Released, the valve stays unpowered while the master keeps its enable on: the chain waits for
  // its reset.
  ASSERT_TRUE(panel.press_estop(false));
  const double released = travel_while_driving(master, kOpening, 200ms);
  EXPECT_LT(std::abs(released), 0.02 * moving) << "the valve was powered again without a reset";
  EXPECT_EQ(panel.input_register(map::input_register::valve_power_cut), 1);

  // The master's reset: enable off, then on.
  ASSERT_TRUE(master.write_enable(false));
  EXPECT_EQ(panel.input_register(map::input_register::valve_power_cut), 0);
  (void)travel_while_driving(master, kOpening, 30ms);
  EXPECT_GT(travel_while_driving(master, kOpening, 200ms), 0.5 * moving) << "the reset did not restore the power";
}

TEST(ModbusSimdevEstop, SignalOnlyWiringLeavesTheValvePowered) {
  Simdev simdev({"--initial-position-m", "0.1", "--estop-signal-only"});
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  Client master(simdev.port());
  Client panel(simdev.port());
  ASSERT_TRUE(master.connected() && panel.connected());
  ASSERT_TRUE(panel.press_estop(true));
  EXPECT_GT(travel_while_driving(master, 0.05f, 200ms), 1000.0);
  EXPECT_EQ(panel.input_register(map::input_register::valve_power_cut), 0);
  std::uint8_t loop_closed = 1;
  ASSERT_EQ(modbus_read_input_bits(panel.get(), map::discrete_input::estop_loop_closed, 1, &loop_closed), 1);
  EXPECT_EQ(loop_closed, 0) << "the e-stop input still opens";
}

}  // namespace
}  // namespace hsa::io
