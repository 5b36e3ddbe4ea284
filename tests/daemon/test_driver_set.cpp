// hsad's driver set: the RT cycle's read_all/write_all masks, and the recovery of failed drivers
// that an operator reset runs on a normal thread (DriverSet::recover), on the loopback fixture
// plugin and on the sim plugin with its driver_error event.
#include "daemon/hsad/driver_set.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <toml++/toml.h>

#include "daemon/config/load_config.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::daemon {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr io::Duration period = 100us;

DriverConfig driver(std::string name, std::string plugin, std::string_view settings) {
  return {std::move(name), std::move(plugin), toml::parse(settings)};
}

// Drivers "a" (fails its second read) and "b" (never fails), both the loopback fixture.
DaemonConfig two_loopbacks() {
  DaemonConfig config;
  config.source = "test";
  config.drivers.push_back(driver("a", HSA_FIXTURE_LOOPBACK_PATH, "fail_read_after = 1"));
  config.drivers.push_back(driver("b", HSA_FIXTURE_LOOPBACK_PATH, ""));
  return config;
}

TEST(DriverSet, AFailedDriverSetsItsBitEveryCycleUntilRecovered) {
  DriverSet set(two_loopbacks());
  set.activate_all();
  const std::uint64_t a = set.mask_of({"a"}), b = set.mask_of({"b"});
  io::Timestamp t{};
  EXPECT_EQ(set.read_all(t, period), 0u);
  EXPECT_EQ(set.write_all(t, period), 0u);
  for (int i = 0; i < 5; ++i) {
    t += period;
    EXPECT_EQ(set.read_all(t, period), a) << i;
    EXPECT_EQ(set.write_all(t, period), a) << i;
  }
  EXPECT_EQ(set.out_of_cycle(a | b), a);
  EXPECT_EQ(set.out_of_cycle(b), 0u);
}

TEST(DriverSet, RecoverBringsBackOnlyTheFailedDriversOfTheMaskWithTheirSlots) {
  DriverSet set(two_loopbacks());
  set.activate_all();
  const std::uint64_t a = set.mask_of({"a"}), b = set.mask_of({"b"});
  io::DriverHandle& handle_a = *set.handles()[0];
  io::DriverHandle& handle_b = *set.handles()[1];
  const io::ChannelSlot* slots_a = handle_a.slots().data();
  io::Timestamp t{};
  (void)set.read_all(t, period);
  t += period;
  ASSERT_EQ(set.read_all(t, period), a);
  const double b_reads = handle_b.slots()[0].value;  // the fixture's enc counts reads since configure

  ASSERT_TRUE(set.recover(b).ok());  // nothing of b's to recover: b is left alone
  EXPECT_EQ(handle_b.state(), io::DriverState::active);
  EXPECT_EQ(set.out_of_cycle(a), a);

  ASSERT_TRUE(set.recover(a | b).ok());
  EXPECT_EQ(set.out_of_cycle(a | b), 0u);
  EXPECT_EQ(handle_a.slots().data(), slots_a);
  t += period;
  EXPECT_EQ(set.read_all(t, period), 0u);
  EXPECT_EQ(set.write_all(t, period), 0u);
  EXPECT_EQ(handle_a.slots()[0].value, 1.0);        // a was configured anew: its first read
  EXPECT_EQ(handle_b.slots()[0].value, b_reads + 1);  // b kept running, never reconfigured

  // A second recover for the same mask (a second axis sharing the driver) finds it running.
  ASSERT_TRUE(set.recover(a).ok());
  t += period;
  EXPECT_EQ(set.read_all(t, period), a);  // fail_read_after = 1: a's second read since configure
}

TEST(DriverSet, TheRtCallsSkippingAFailedDriverAllocateNothing) {
  DriverSet set(two_loopbacks());
  set.activate_all();
  io::Timestamp t{};
  (void)set.read_all(t, period);
  (void)set.write_all(t, period);
  t += period;
  ASSERT_NE(set.read_all(t, period), 0u);
  const std::uint64_t both = set.mask_of({"a", "b"});
  const long before = test::process_allocations();
  for (int i = 0; i < 100; ++i) {
    t += period;
    (void)set.read_all(t, period);
    (void)set.write_all(t, period);
    set.make_safe(both);  // as the cycle does for a failed driver
  }
  EXPECT_EQ(test::process_allocations(), before);
}

// The loopback fixture counts make_safe calls in a function it exports. The test holds the
// library open itself, so the count outlives the drivers.
struct LoopbackLibrary {
  void* lib = dlopen(HSA_FIXTURE_LOOPBACK_PATH, RTLD_NOW);
  ~LoopbackLibrary() {
    if (lib != nullptr) dlclose(lib);
  }
  std::uint64_t make_safe_calls() const {
    using Count = std::uint64_t (*)();
    const auto count = lib ? reinterpret_cast<Count>(dlsym(lib, "fixture_loopback_make_safe_calls")) : nullptr;
    return count != nullptr ? count() : UINT64_MAX;
  }
};

TEST(DriverSet, MakeSafeReachesTheFailedDriverAndItsReasonIsKept) {
  const LoopbackLibrary library;
  const auto loopback_make_safe_calls = [&] { return library.make_safe_calls(); };
  auto set = std::make_unique<DriverSet>(two_loopbacks());
  set->activate_all();
  const std::uint64_t a = set->mask_of({"a"}), b = set->mask_of({"b"});
  io::Timestamp t{};
  (void)set->read_all(t, period);
  t += period;
  ASSERT_EQ(set->read_all(t, period), a);
  const std::uint64_t before = loopback_make_safe_calls();
  ASSERT_NE(before, UINT64_MAX);
  set->make_safe(a);
  EXPECT_EQ(loopback_make_safe_calls(), before + 1);
  EXPECT_EQ(set->failures_of(a | b), "'a': read failed: fixture read failure injected");
  EXPECT_EQ(set->failures_of(b), "");
  // Destroying the set (every way out of hsad) makes both safe before they deactivate, and the
  // failed one once more from its handle, before on_error releases it.
  set.reset();
  EXPECT_EQ(loopback_make_safe_calls(), before + 4);
}

TEST(DriverSet, RecoversTheSimPluginAfterItsDriverErrorEvent) {
  DaemonConfig config;
  config.source = "test";
  config.drivers.push_back(driver("rig", "sim",
                                  "timing = \"lockstep\"\n"
                                  "[[events]]\nat_s = 0.001\ndriver_error = true\ndriver_error_s = 0.001\n"));
  DriverSet set(config);
  set.activate_all();
  const std::uint64_t rig = set.mask_of({"rig"});
  io::DriverHandle& handle = *set.handles()[0];
  const io::ChannelSlot* slots = handle.slots().data();
  io::Timestamp t{};
  int ok_cycles = 0;
  for (; ok_cycles < 100 && set.read_all(t, period) == 0; ++ok_cycles, t += period) {
    (void)set.write_all(t, period);
  }
  ASSERT_LT(ok_cycles, 100) << "the driver_error event did not fire";
  EXPECT_EQ(set.out_of_cycle(rig), rig);

  t += 2ms;  // past the 1 ms outage, on the daemon's clock
  const io::Result r = set.recover(rig);
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(handle.state(), io::DriverState::active);
  EXPECT_EQ(handle.slots().data(), slots);
  EXPECT_EQ(set.read_all(t, period), 0u);
  EXPECT_EQ(set.write_all(t, period), 0u);
  EXPECT_EQ(handle.slots()[*handle.find_channel("encoder")].timestamp, t);  // read again
}

}  // namespace
}  // namespace hsa::daemon

namespace hsa::daemon {
namespace {

DaemonConfig sim_config(const std::string& settings) {
  DaemonConfig config;
  config.source = "rig.toml";
  config.drivers.push_back({"rig", "sim", toml::parse(settings)});
  return config;
}

// hsad --check-config: each plugin checks its own settings, with no device opened.
TEST(CheckDriverSettings, APluginRefusesItsBadSettingsNamingTheFileDriverAndKey) {
  EXPECT_THAT(plan_drivers(sim_config("valve = 'servo'\nload_kg = 3.0\n")).refused, ::testing::IsEmpty());
  const auto banana = plan_drivers(sim_config("valve = 'banana'\n")).refused;
  ASSERT_EQ(banana.size(), 1u);
  EXPECT_EQ(banana[0], R"(rig.toml: drivers 'rig' (plugin sim): valve: expected "servo" or "proportional", got "banana")");
  const auto nan_load = plan_drivers(sim_config("load_kg = nan\n")).refused;
  ASSERT_EQ(nan_load.size(), 1u);
  EXPECT_THAT(nan_load[0], ::testing::HasSubstr("load_kg: expected a finite number >= 0 kg, got nan"));
}

// What hsad --check-config asks of each plugin passes on the shipped simulated rigs, the one with
// a configured rig ([drivers.settings.rig]) included.
TEST(CheckDriverSettings, TheShippedSimulatedRigsPass) {
  for (const char* file : {"hsad-sim.toml", "hsad-sim-two-axes.toml", "hsad-sim-proportional.toml",
                           "hsad-sim-custom-rig.toml"}) {
    EXPECT_THAT(plan_drivers(load_config(std::string(HSA_SOURCE_DIR) + "/systemd/" + file)).refused,
                ::testing::IsEmpty())
        << file;
  }
}

// Read from a file, the plugin's settings keep their places: the message starts with the line
// and column of the value, as every other configuration error does.
TEST(CheckDriverSettings, APluginsMessageNamesTheLineAndColumnInTheFile) {
  std::ifstream in(std::string(HSA_SOURCE_DIR) + "/systemd/hsad-sim.toml");
  std::ostringstream file;
  file << in.rdbuf();
  std::string text = file.str();
  const std::string servo = "valve = \"servo\"";
  const std::size_t at = text.find(servo);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, servo.size(), "valve = \"banana\"");
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');

  const auto failures = plan_drivers(parse_config(text, "hsad-sim.toml")).refused;
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0], "hsad-sim.toml:" + std::to_string(line) +
                             R"(:9: drivers 'rig' (plugin sim): valve: expected "servo" or "proportional", got "banana")");
}

TEST(CheckDriverSettings, AnUnknownPluginIsNamed) {
  DaemonConfig config = sim_config("");
  config.drivers[0].plugin = "no_such_plugin";
  const auto failures = plan_drivers(config).refused;
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_THAT(failures[0], ::testing::HasSubstr("drivers 'rig' (plugin no_such_plugin): "));
  EXPECT_THAT(failures[0], ::testing::HasSubstr("libhsa_driver_no_such_plugin.so"));
}

}  // namespace
}  // namespace hsa::daemon
