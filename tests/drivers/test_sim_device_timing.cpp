// The sim plugin with timing = "device": the rig runs on the plugin's device thread, on its own
// clock, and the RT side only takes its latest readings and leaves commands for it. Wall-clock
// waits here are bounded polls for something the device must do, never a timing assertion.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dirent.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include <toml++/toml.h>

#include "drivers/plugin_loader.hpp"
#include "tests/drivers/sim_plugin.hpp"
#include "drivers/signal_binding.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr Duration period = kSimTestPeriod;

// Threads of this process named as the plugin names its device thread (/proc/self/task/*/comm).
int device_threads() {
  int n = 0;
  if (DIR* d = opendir("/proc/self/task")) {
    while (const dirent* e = readdir(d)) {
      if (e->d_name[0] == '.') continue;
      std::ifstream comm(std::string("/proc/self/task/") + e->d_name + "/comm");
      std::string name;
      std::getline(comm, name);
      n += name == "hsa-sim-device";
    }
    closedir(d);
  }
  return n;
}

// A proportional-valve rig on the device clock, its signals bound as hsad binds them.
struct DeviceRig {
  explicit DeviceRig(const std::string& extra = "")
      : driver(load_sim("valve = \"proportional\"\ntiming = \"device\"\nseed = 5\n" + extra)),
        position(bind_encoder_input("x", *driver, "encoder")),
        spool(bind_analog_input("spool", *driver, "spool_lvdt")),
        current(bind_analog_input("i", *driver, "valve_current")),
        current_ref(bind_analog_output("i_ref", *driver, "current_ref")),
        enable(bind_digital_output("en", *driver, "valve_enable")) {}

  void cycle() {
    ASSERT_EQ(driver->read(t, period), IoStatus::ok);
    ASSERT_EQ(driver->write(t, period), IoStatus::ok);
    t += period;
  }
  // Cycles every 100 µs of wall time until `done` holds, for at most 5 s; true if it held.
  template <typename Done>
  bool cycle_until(Done done) {
    const auto give_up = std::chrono::steady_clock::now() + 5s;
    while (std::chrono::steady_clock::now() < give_up) {
      cycle();
      if (done()) return true;
      std::this_thread::sleep_for(100us);
    }
    return false;
  }

  std::unique_ptr<DriverHandle> driver;
  AnalogInput position, spool, current;
  AnalogOutput current_ref;
  DigitalOutput enable;
  Timestamp t{};
};

TEST(SimDeviceTiming, TheRigRunsOnItsOwnThreadWhichStopsWithTheLastRig) {
  ASSERT_EQ(device_threads(), 0);
  {
    DeviceRig a;
    EXPECT_EQ(device_threads(), 1);
    {
      DeviceRig b("initial_position_m = 0.1\n");
      EXPECT_EQ(device_threads(), 1);  // one device thread for every device-timed rig
    }
    EXPECT_EQ(device_threads(), 1);
  }
  EXPECT_EQ(device_threads(), 0);
  // A lockstep rig starts none.
  const auto lockstep = load_sim("valve = \"proportional\"\ntiming = \"lockstep\"");
  EXPECT_EQ(device_threads(), 0);
}

TEST(SimDeviceTiming, TheCommandReachesTheRigWithoutReadsSteppingIt) {
  DeviceRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.current_ref.set(2.0);
  // The device steps the rig on its own: the solenoid current follows the command while the RT
  // side only reads, the rod moves.
  ASSERT_TRUE(rig.cycle_until([&] { return rig.current.sample().value > 1.9; }));
  const double start = rig.position.sample().value;
  ASSERT_TRUE(rig.cycle_until([&] { return rig.position.sample().value > start + 1e-3; }));
  // Reads alone, with no wall time between them, do not step it: the readings of one device step
  // are read back unchanged (the LVDT's noise changes them at every step).
  EXPECT_TRUE(rig.cycle_until([&] {
    const double first = rig.spool.sample().value;
    rig.cycle();
    return rig.spool.sample().value == first;
  }));
}

TEST(SimDeviceTiming, MakeSafeReachesTheDeviceAndHoldsUntilTheNextActivation) {
  DeviceRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.current_ref.set(2.5);
  ASSERT_TRUE(rig.cycle_until([&] { return rig.current.sample().value > 2.4; }));
  rig.driver->make_safe();
  // The amplifier off at the device: its current falls to zero although write() keeps sending.
  EXPECT_TRUE(rig.cycle_until([&] { return rig.current.sample().value < 0.01; }));
  for (int i = 0; i < 50; ++i) rig.cycle();
  EXPECT_LT(rig.current.sample().value, 0.01);
  ASSERT_TRUE(rig.driver->deactivate().ok());
  ASSERT_TRUE(rig.driver->activate().ok());
  EXPECT_TRUE(rig.cycle_until([&] { return rig.current.sample().value > 2.4; }));
}

TEST(SimDeviceTiming, ReadAndWriteDoNotAllocate) {
  DeviceRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.current_ref.set(1.5);
  rig.cycle();
  const long before = hsa::test::process_allocations();
  for (int i = 0; i < 1000; ++i) rig.cycle();
  rig.driver->make_safe();
  rig.cycle();
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
}

TEST(SimDeviceTiming, SettingsTheDeviceCannotHonourAreRefused) {
  const auto message = [](const std::string& settings) -> std::string {
    try {
      (void)load_sim(settings);
    } catch (const PluginError& e) {
      return e.what();
    }
    ADD_FAILURE() << "configured: " << settings;
    return {};
  };
  EXPECT_THAT(message("timing = \"device\"\n[[events]]\nat_s = 0.1\nestop = true"),
              HasSubstr("events: expected no [[events]] with timing = \"device\""));
  EXPECT_THAT(message("device_priority = 50"), HasSubstr("device_priority: expected only with timing = \"device\""));
  EXPECT_THAT(message("timing = \"lockstep\"\ndevice_cpu = 0"), HasSubstr("device_cpu: expected only with timing = \"device\""));
  EXPECT_THAT(message("timing = \"device\"\ndevice_priority = 100"), HasSubstr("device_priority: expected an integer in [0, 99]"));
  // Rigs of one process share the device thread, so a second one must ask for the same.
  DeviceRig first;
  EXPECT_THAT(message("timing = \"device\"\nstep_s = 5e-5"),
              HasSubstr("the rigs of one process share one device thread, running at step 100000 ns, "
                        "priority 0, cpu -1; this rig asks for step 50000 ns"));
  ASSERT_TRUE(first.driver->activate().ok());  // the first is unaffected by the refusal
  first.cycle();
}

}  // namespace
}  // namespace hsa::io
