// The gpiod plugin against the real Linux GPIO character device: a gpio-sim chip, inside the qemu
// VM that tests/kernel boots (this machine's kernel has no GPIO). Built as `kernel_gpiod_sim`,
// not registered with ctest on the host; the VM harness runs it.
//
// The harness provides:
//   HSA_GPIO_SIM_CHIP   the chip's device, e.g. /dev/gpiochip0, with 8 lines named
//                       0 hsa-estop, 1 hsa-valve-enable, 2 hsa-pump-enable, 3 hsa-limit-low, 4-7 unnamed
//   HSA_GPIO_SIM_SYSFS  the directory holding sim_gpio0 .. sim_gpio7, each with `pull` (write
//                       "pull-up"/"pull-down" to drive an input) and `value` (what an output drives)
//   HSA_PLUGIN_DIR      where libhsa_driver_gpiod.so is (default: the build tree's plugin dir)
// Without a chip it prints why and exits 77, which ctest's SKIP_RETURN_CODE turns into SKIP.
//
// Every line change is made through gpio-sim's sysfs files and every output checked there: the
// plugin is seen only from outside, through the kernel, as a real board would see it.
#include <gpiod.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>

#include <toml++/toml.h>

#include "drivers/plugin_error.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/kernel/gpio_sim_lines.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

using test::gpio_sim::env;
using test::gpio_sim::pull;
using test::gpio_sim::sim_value;

const std::string& chip_path() {
  static const std::string path = env("HSA_GPIO_SIM_CHIP");
  return path;
}

std::string plugin_dir() {
  const std::string dir = env("HSA_PLUGIN_DIR");
  return dir.empty() ? HSA_PLUGIN_DIR : dir;
}

std::unique_ptr<DriverHandle> load(const std::string& channels) {
  return PluginLoader({plugin_dir()})
      .load_driver("gpio", "gpiod", toml::parse("chip = \"" + chip_path() + "\"\n" + channels));
}

std::string configure_error(const std::string& channels) {
  try {
    (void)load(channels);
  } catch (const PluginError& e) {
    EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
    return e.what();
  }
  return "(configured)";
}

// The kernel's view of a line: who holds it. Read through a chip handle of our own.
struct Kernel {
  Kernel() : chip(gpiod_chip_open(chip_path().c_str())) {}
  ~Kernel() {
    if (chip != nullptr) gpiod_chip_close(chip);
  }
  Kernel(const Kernel&) = delete;
  Kernel& operator=(const Kernel&) = delete;

  std::string consumer(unsigned int offset) const {
    gpiod_line* line = gpiod_chip_get_line(chip, offset);
    if (line == nullptr || gpiod_line_update(line) != 0) return "(error)";
    const char* c = gpiod_line_consumer(line);
    return gpiod_line_is_used(line) ? (c != nullptr ? c : "(unnamed)") : "";
  }

  gpiod_chip* chip;
};

constexpr const char* estop_by_name = R"(
[[channels]]
name = "estop"
kind = "digital_input"
line = "hsa-estop"
edge_events = true
)";

class GpioSim : public ::testing::Test {
 protected:
  void SetUp() override {
    // The inputs start pulled down, as gpio-sim creates them.
    pull(0, false);
    pull(3, false);
  }

  // One daemon cycle's read, returning the channel's value; checks status and timestamp.
  double read(DriverHandle& d, const char* channel) {
    t_ += 1ms;
    EXPECT_EQ(d.read(t_, 1ms), IoStatus::ok);
    const auto i = d.find_channel(channel);
    EXPECT_TRUE(i.has_value()) << channel;
    const ChannelSlot& s = d.slots()[*i];
    EXPECT_EQ(s.status, SampleStatus::ok);
    EXPECT_EQ(s.timestamp, t_);
    return s.value;
  }

  void write(DriverHandle& d, const char* channel, double value) {
    const auto i = d.find_channel(channel);
    ASSERT_TRUE(i.has_value()) << channel;
    d.slots()[*i].value = value;
    EXPECT_EQ(d.write(t_, 1ms), IoStatus::ok);
  }

  Timestamp t_{};
};

// (a) The e-stop input follows the line's edges, each seen on the very next read.
TEST_F(GpioSim, EstopFollowsTheLineOnTheNextRead) {
  auto d = load(estop_by_name);
  EXPECT_EQ(read(*d, "estop"), 0.0);
  pull(0, true);
  EXPECT_EQ(read(*d, "estop"), 1.0);
  EXPECT_EQ(read(*d, "estop"), 1.0);  // and stays: no stale event read as a pulse
  pull(0, false);
  EXPECT_EQ(read(*d, "estop"), 0.0);
  EXPECT_EQ(read(*d, "estop"), 0.0);
}

// (a) A pulse that starts and ends between two reads is latched for one cycle. The same pulse on
// a plain input (no edge events) is not seen at all: the latch is what catches it.
TEST_F(GpioSim, APulseBetweenTwoReadsIsLatched) {
  auto d = load(std::string(estop_by_name) + R"(
[[channels]]
name = "limit_low"
kind = "digital_input"
line = "hsa-limit-low"
)");
  EXPECT_EQ(read(*d, "estop"), 0.0);
  EXPECT_EQ(read(*d, "limit_low"), 0.0);

  pull(0, true);
  pull(0, false);
  pull(3, true);
  pull(3, false);
  ASSERT_EQ(sim_value(0), 0);  // both lines are back at rest before the read
  ASSERT_EQ(sim_value(3), 0);
  EXPECT_EQ(read(*d, "estop"), 1.0);      // the pulse, stretched to this cycle
  EXPECT_EQ(read(*d, "limit_low"), 0.0);  // a plain input only sees the level
  EXPECT_EQ(read(*d, "estop"), 0.0);      // then the level again

  // The other way round: resting high, a pulse low.
  pull(0, true);
  EXPECT_EQ(read(*d, "estop"), 1.0);
  pull(0, false);
  pull(0, true);
  EXPECT_EQ(read(*d, "estop"), 0.0);
  EXPECT_EQ(read(*d, "estop"), 1.0);
}

// (a) active_low inverts the channel, for the level and for the latched pulse.
TEST_F(GpioSim, ActiveLowInverts) {
  auto d = load(std::string(estop_by_name) + "active_low = true\n");
  EXPECT_EQ(read(*d, "estop"), 1.0);  // pulled down: active
  pull(0, true);
  EXPECT_EQ(read(*d, "estop"), 0.0);
  pull(0, false);
  pull(0, true);
  EXPECT_EQ(read(*d, "estop"), 1.0);  // the low pulse, as active
  EXPECT_EQ(read(*d, "estop"), 0.0);
}

// (b) Outputs: driven at their safe value from configure, following write() when active, and back
// to the safe value on deactivate. gpio-sim's `value` shows what the line is driven to.
TEST_F(GpioSim, OutputsFollowWriteAndGoSafeOnDeactivate) {
  auto d = load(R"(
[[channels]]
name = "valve_enable"
kind = "digital_output"
line = "hsa-valve-enable"
safe_value = false
[[channels]]
name = "pump_enable"
kind = "digital_output"
line = "hsa-pump-enable"
active_low = true
safe_value = false
[[channels]]
name = "brake_release"
kind = "digital_output"
line = 4
safe_value = true
)");
  EXPECT_EQ(sim_value(1), 0);
  EXPECT_EQ(sim_value(2), 1);  // active low: inactive is high
  EXPECT_EQ(sim_value(4), 1);

  ASSERT_TRUE(d->activate().ok());
  write(*d, "valve_enable", 1.0);
  EXPECT_EQ(sim_value(1), 1);
  write(*d, "valve_enable", 0.0);
  EXPECT_EQ(sim_value(1), 0);
  write(*d, "valve_enable", 1.0);
  write(*d, "pump_enable", 1.0);
  write(*d, "brake_release", 0.0);
  EXPECT_EQ(sim_value(1), 1);
  EXPECT_EQ(sim_value(2), 0);
  EXPECT_EQ(sim_value(4), 0);

  const Result r = d->deactivate();
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(sim_value(1), 0);
  EXPECT_EQ(sim_value(2), 1);
  EXPECT_EQ(sim_value(4), 1);
}

// A charge pump (drivers/gpiod/charge_pump.hpp) toggles its line on every divisor-th write()
// while active and enabled, whatever its slot says, and sits at its safe level before activation
// and after deactivation; an ordinary output beside it still follows its slot.
TEST_F(GpioSim, AChargePumpTogglesOnWriteAndStopsSafeOnDeactivate) {
  auto d = load(R"(
[[channels]]
name = "valve_enable"
kind = "digital_output"
line = "hsa-valve-enable"
[[channels]]
name = "charge_pump"
kind = "digital_output"
line = 5
charge_pump = true
enabled_by = ["valve_enable"]
divisor = 2
)");
  EXPECT_EQ(sim_value(5), 0);  // configured: safe
  ASSERT_TRUE(d->activate().ok());
  EXPECT_EQ(sim_value(5), 0);
  write(*d, "valve_enable", 1.0);
  std::string levels = std::to_string(sim_value(5));
  for (int i = 0; i < 7; ++i) {
    write(*d, "charge_pump", i % 2);  // ignored: the driver drives the pump
    levels += static_cast<char>('0' + sim_value(5));
  }
  EXPECT_EQ(levels, "01100110");
  write(*d, "valve_enable", 1.0);
  EXPECT_EQ(sim_value(1), 1);
  EXPECT_EQ(sim_value(5), 0);  // the ninth write: still low (divisor 2)
  write(*d, "valve_enable", 1.0);
  EXPECT_EQ(sim_value(5), 1);  // the tenth: high
  // No write(): no edge. The relay watching the line sees the wave stop, high here.
  EXPECT_EQ(d->read(t_ + 1ms, 1ms), IoStatus::ok);
  EXPECT_EQ(sim_value(5), 1);

  const Result r = d->deactivate();
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(sim_value(5), 0);
  EXPECT_EQ(sim_value(1), 0);
  // Activated again, the wave restarts from the safe level.
  ASSERT_TRUE(d->activate().ok());
  levels.clear();
  for (int i = 0; i < 4; ++i) {
    write(*d, "valve_enable", 1.0);
    levels += static_cast<char>('0' + sim_value(5));
  }
  EXPECT_EQ(levels, "0110");
  ASSERT_TRUE(d->deactivate().ok());
  EXPECT_EQ(sim_value(5), 0);
}

// The pump's enable (enabled_by): in the write() that turns any of its enables off, the line goes
// to its safe level, high or low as the wave was, and stays there while an enable is off, however
// its own slot is set; with every enable on again the wave restarts from the safe level. hsad
// writes a valve enable off in the cycle its axis leaves ENABLED, so this is the relay dropping
// in that cycle.
TEST_F(GpioSim, AChargePumpStopsInTheWriteThatTurnsAnEnableOff) {
  auto d = load(R"(
[[channels]]
name = "x_enable"
kind = "digital_output"
line = "hsa-valve-enable"
[[channels]]
name = "charge_pump"
kind = "digital_output"
line = 5
charge_pump = true
enabled_by = ["x_enable", "y_enable"]
[[channels]]
name = "y_enable"
kind = "digital_output"
line = 4
)");
  ASSERT_TRUE(d->activate().ok());
  const auto x = *d->find_channel("x_enable");
  const auto y = *d->find_channel("y_enable");
  const auto pump = *d->find_channel("charge_pump");
  d->slots()[pump].value = 1.0;  // ignored throughout
  // One write per character of `enables` ("xy": 1 on, 0 off); the pump's line after each.
  const auto run = [&](std::initializer_list<const char*> enables) {
    std::string levels;
    for (const char* e : enables) {
      d->slots()[x].value = e[0] == '1' ? 1.0 : 0.0;
      d->slots()[y].value = e[1] == '1' ? 1.0 : 0.0;
      t_ += 1ms;
      EXPECT_EQ(d->write(t_, 1ms), IoStatus::ok);
      EXPECT_EQ(sim_value(1), e[0] - '0');
      EXPECT_EQ(sim_value(4), e[1] - '0');
      levels += static_cast<char>('0' + sim_value(5));
    }
    return levels;
  };
  EXPECT_EQ(run({"00", "10", "01"}), "000");                // not both on: no wave from activation
  EXPECT_EQ(run({"11", "11", "11", "11", "11"}), "10101");  // both on: a toggle per write, now high
  EXPECT_EQ(run({"10"}), "0");                              // y off: low in that very write
  EXPECT_EQ(run({"10", "10", "00", "01", "10"}), "00000");  // and stays low
  EXPECT_EQ(run({"11", "11"}), "10");                       // both on again: from the safe level
  EXPECT_EQ(run({"11", "01", "01"}), "100");                // x off while high: low at once
  EXPECT_EQ(run({"11", "11", "11"}), "101");
}

// (c) A line another program holds fails configure, naming the key, the chip, the line and the
// holder; and the lines the driver had already taken are given back.
TEST_F(GpioSim, ABusyLineNamesItsConsumer) {
  Kernel k;
  ASSERT_NE(k.chip, nullptr);
  gpiod_line* held = gpiod_chip_get_line(k.chip, 1);
  ASSERT_NE(held, nullptr);
  ASSERT_EQ(gpiod_line_request_output(held, "other", 0), 0);

  const std::string error = configure_error(std::string(estop_by_name) + R"(
[[channels]]
name = "valve_enable"
kind = "digital_output"
line = "hsa-valve-enable"
)");
  EXPECT_THAT(error, HasSubstr("channels[1].line"));
  EXPECT_THAT(error, HasSubstr("line 'hsa-valve-enable' (offset 1) of " + std::string(gpiod_chip_name(k.chip))));
  EXPECT_THAT(error, HasSubstr("is busy: it is held by consumer 'other'"));
  EXPECT_EQ(k.consumer(0), "");  // the e-stop line, requested before the failure, is free again
  gpiod_line_release(held);
}

// (d) A line by name and a line by offset are the lines the kernel has under those; the driver
// holds them as "hsad" while configured and lets them go on cleanup.
TEST_F(GpioSim, LinesAreFoundByNameAndByOffset) {
  Kernel k;
  ASSERT_NE(k.chip, nullptr);
  {
    auto d = load(std::string(estop_by_name) + R"(
[[channels]]
name = "limit_low"
kind = "digital_input"
line = 3
)");
    EXPECT_EQ(k.consumer(0), "hsad");
    EXPECT_EQ(k.consumer(3), "hsad");
    EXPECT_EQ(k.consumer(1), "");
    pull(3, true);
    EXPECT_EQ(read(*d, "limit_low"), 1.0);
    EXPECT_EQ(read(*d, "estop"), 0.0);
    pull(0, true);
    pull(3, false);
    EXPECT_EQ(read(*d, "limit_low"), 0.0);
    EXPECT_EQ(read(*d, "estop"), 1.0);
  }
  EXPECT_EQ(k.consumer(0), "");
  EXPECT_EQ(k.consumer(3), "");
}

TEST_F(GpioSim, WrongLinesAreRefusedWithWhatExists) {
  EXPECT_THAT(configure_error("[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = \"hsa-nope\"\n"),
              HasSubstr("channels[0].line: no line named 'hsa-nope' on chip"));
  EXPECT_THAT(configure_error("[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = \"hsa-nope\"\n"),
              HasSubstr("'hsa-estop', 'hsa-valve-enable', 'hsa-pump-enable', 'hsa-limit-low'"));
  EXPECT_THAT(configure_error("[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = 8\n"),
              HasSubstr("channels[0].line: expected an offset below 8"));
  // One line by name and by offset: only the kernel knows they are the same.
  EXPECT_THAT(configure_error(std::string(estop_by_name) +
                              "[[channels]]\nname = \"b\"\nkind = \"digital_input\"\nline = 0\n"),
              HasSubstr("channels[1].line: expected a line no other channel uses, got line "
                        "'hsa-estop' (offset 0)"));
}

// read() and write() allocate nothing, also when edges are drained.
TEST_F(GpioSim, TheCycleAllocatesNothing) {
  auto d = load(std::string(estop_by_name) + R"(
[[channels]]
name = "limit_low"
kind = "digital_input"
line = 3
[[channels]]
name = "valve_enable"
kind = "digital_output"
line = 1
[[channels]]
name = "charge_pump"
kind = "digital_output"
line = 5
charge_pump = true
enabled_by = ["valve_enable"]
)");
  ASSERT_TRUE(d->activate().ok());
  const auto estop = *d->find_channel("estop");
  const auto enable = *d->find_channel("valve_enable");
  long allocations = 0;
  int pulses_seen = 0;
  for (int cycle = 0; cycle < 200; ++cycle) {
    if (cycle % 10 == 0) {  // a pulse on the e-stop every tenth cycle, outside the counted calls
      pull(0, true);
      pull(0, false);
    }
    d->slots()[enable].value = cycle % 50 == 49 ? 0.0 : 1.0;  // the pump stopped now and then
    t_ += 1ms;
    const long before = test::process_allocations();
    const IoStatus r = d->read(t_, 1ms);
    const IoStatus w = d->write(t_, 1ms);
    allocations += test::process_allocations() - before;
    ASSERT_EQ(r, IoStatus::ok);
    ASSERT_EQ(w, IoStatus::ok);
    pulses_seen += d->slots()[estop].value == 1.0 ? 1 : 0;
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(pulses_seen, 20);  // every pulse seen, each for exactly one cycle
  EXPECT_EQ(sim_value(5), 0);  // the last write had the pump's enable off: safe
}

}  // namespace
}  // namespace hsa::io

int main(int argc, char** argv) {
  const std::string chip = hsa::test::gpio_sim::env("HSA_GPIO_SIM_CHIP");
  const std::string sysfs = hsa::test::gpio_sim::env("HSA_GPIO_SIM_SYSFS");
  if (chip.empty()) {
    std::printf("SKIP: HSA_GPIO_SIM_CHIP is not set. This test runs inside the qemu VM of tests/kernel, "
                "which creates a gpio-sim chip and sets it (this kernel may have no GPIO at all).\n");
    return 77;
  }
  if (!std::filesystem::exists(chip)) {
    std::printf("SKIP: HSA_GPIO_SIM_CHIP=%s does not exist: no gpio-sim chip.\n", chip.c_str());
    return 77;
  }
  if (sysfs.empty() || !std::filesystem::exists(sysfs + "/sim_gpio0/pull")) {
    std::printf("SKIP: HSA_GPIO_SIM_SYSFS=%s does not hold sim_gpio0/pull: no gpio-sim sysfs to drive "
                "the lines with.\n", sysfs.c_str());
    return 77;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
