// The sim driver plugin, loaded the way the daemon loads it (by name, from the build's plugin
// directory) and driven through bound signals in lockstep.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>

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

// The signals a daemon would bind for a rig with a servo-valve.
struct ServoRig {
  explicit ServoRig(const std::string& extra_settings = "")
      : driver(load_sim("valve = \"servo\"\ntiming = \"lockstep\"\nseed = 3\n" + extra_settings)),
        position(bind_encoder_input("rod_position", *driver, "encoder")),
        pressure_a(bind_analog_input("pressure_a", *driver, "pressure_a")),
        pressure_b(bind_analog_input("pressure_b", *driver, "pressure_b")),
        estop(bind_digital_input("estop", *driver, "estop", {.invert = true})),
        opening(bind_analog_output("valve_opening", *driver, "opening_cmd",
                                   {.low_limit = -1.0, .high_limit = 1.0})),
        enable(bind_digital_output("valve_enable", *driver, "valve_enable")) {}

  // One daemon cycle: read, then write the latched outputs.
  void cycle() {
    ASSERT_EQ(driver->read(t, period), IoStatus::ok);
    ASSERT_EQ(driver->write(t, period), IoStatus::ok);
    t += period;
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) cycle();
  }

  std::unique_ptr<DriverHandle> driver;
  AnalogInput position, pressure_a, pressure_b;
  DigitalInput estop;
  AnalogOutput opening;
  DigitalOutput enable;
  Timestamp t{};
};

TEST(SimDriver, DeclaresTheChannelsOfAServoValveRig) {
  const auto driver = load_sim("valve = \"servo\"");
  EXPECT_EQ(driver->plugin().name(), "sim");
  std::string names;
  for (const auto& c : driver->channels()) names += c.name + ":" + c.unit + " ";
  EXPECT_EQ(names, "encoder:m pressure_a:Pa pressure_b:Pa opening_cmd:1 valve_enable:1 estop:1 ");
}

TEST(SimDriver, DeclaresTheChannelsOfAProportionalValveRig) {
  const auto driver = load_sim("valve = \"proportional\"");
  std::string names;
  for (const auto& c : driver->channels()) names += c.name + ":" + c.unit + " ";
  EXPECT_EQ(names,
            "encoder:m pressure_a:Pa pressure_b:Pa spool_lvdt:m valve_current:A current_ref:A "
            "valve_enable:1 estop:1 ");
  // A servo-valve command cannot be bound to a proportional rig.
  EXPECT_THROW((void)bind_analog_output("u", *driver, "opening_cmd"), BindingError);
}

TEST(SimDriver, EncoderFollowsTheCommandedOpening) {
  ServoRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.run(10);
  const double start = rig.position.sample().value;
  EXPECT_TRUE(rig.position.sample().ok());
  EXPECT_EQ(rig.position.sample().timestamp, rig.t - period);

  rig.opening.set(0.3);
  rig.run(2000);  // 0.2 s of simulated time
  const double extended = rig.position.sample().value;
  EXPECT_GT(extended - start, 1e-3);

  rig.opening.set(-0.3);
  rig.run(2000);
  EXPECT_LT(rig.position.sample().value - extended, -1e-3);
  EXPECT_TRUE(rig.pressure_a.sample().ok());
  EXPECT_GT(rig.pressure_a.sample().value, 0.0);
}

TEST(SimDriver, ProportionalValveCurrentMovesTheRodBothWays) {
  const auto driver = load_sim("valve = \"proportional\"\ntiming = \"lockstep\"");
  const AnalogInput position = bind_encoder_input("x", *driver, "encoder");
  const AnalogInput current = bind_analog_input("i", *driver, "valve_current");
  AnalogOutput current_ref = bind_analog_output("i_ref", *driver, "current_ref");
  DigitalOutput enable = bind_digital_output("en", *driver, "valve_enable");
  ASSERT_TRUE(driver->activate().ok());
  Timestamp t{};
  const auto run = [&](int cycles) {
    for (int i = 0; i < cycles; ++i, t += period) {
      ASSERT_EQ(driver->read(t, period), IoStatus::ok);
      ASSERT_EQ(driver->write(t, period), IoStatus::ok);
    }
  };
  enable.set(true);
  run(10);
  const double start = position.sample().value;
  current_ref.set(3.0);  // I_max: spool to its end stop, P→A fully open
  run(2000);
  EXPECT_GT(position.sample().value - start, 1e-3);
  EXPECT_NEAR(current.sample().value, 3.0, 0.05);
  const double extended = position.sample().value;
  current_ref.set(0.6);  // below the bias current: the spool crosses to B and the rod retracts
  run(2000);
  const double retracted = position.sample().value;
  EXPECT_LT(retracted - extended, -1e-3);
  current_ref.set(0.0);  // de-energized: the spool rests in its fail-safe zone, ports blocked
  run(500);
  const double held = position.sample().value;
  run(2000);
  EXPECT_NEAR(position.sample().value, held, 1e-4);
}

TEST(SimDriver, OutputsAreInertUntilActivatedAndAfterDeactivation) {
  ServoRig rig;
  rig.enable.set(true);
  rig.opening.set(0.5);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(rig.driver->read(Timestamp{i * period}, period), IoStatus::ok);
  const double before_activation = rig.position.sample().value;
  EXPECT_NEAR(before_activation, 0.150, 1e-4);  // the configured initial position, held

  ASSERT_TRUE(rig.driver->activate().ok());
  rig.run(1000);
  const double moved = rig.position.sample().value;
  EXPECT_GT(moved - before_activation, 1e-3);

  // Amplifier off: the servo-valve centres and, once the rod has coasted to a stop, holds it.
  ASSERT_TRUE(rig.driver->deactivate().ok());
  for (int i = 0; i < 500; ++i) ASSERT_EQ(rig.driver->read(rig.t, period), IoStatus::ok);
  const double stopped = rig.position.sample().value;
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(rig.driver->read(rig.t, period), IoStatus::ok);
  EXPECT_NEAR(rig.position.sample().value, stopped, 1e-4);
}

TEST(SimDriver, MakeSafeSwitchesTheValveOffUntilTheNextActivation) {
  ServoRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.opening.set(0.5);
  rig.run(1000);
  const double moving_from = rig.position.sample().value;
  rig.run(500);
  ASSERT_GT(rig.position.sample().value - moving_from, 1e-3);  // the valve is open: the rod moves

  rig.driver->make_safe();
  EXPECT_EQ(rig.driver->state(), DriverState::active);
  rig.run(500);  // the rod coasts to a stop; write() keeps sending the open command
  const double stopped = rig.position.sample().value;
  rig.run(1000);
  EXPECT_NEAR(rig.position.sample().value, stopped, 1e-4);

  // A new activation lets the commands through again.
  ASSERT_TRUE(rig.driver->deactivate().ok());
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.run(1000);
  EXPECT_GT(rig.position.sample().value - stopped, 1e-3);
}

TEST(SimDriver, EstopReachesTheSampleWhenScheduled) {
  ServoRig rig("[[events]]\nat_s = 0.001\nestop = true\n[[events]]\nat_s = 0.002\nestop = false\n");
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.run(9);  // 9 lockstep steps: 0.9 ms
  EXPECT_FALSE(rig.estop.sample().value);
  EXPECT_EQ(rig.driver->slots()[*rig.driver->find_channel("estop")].value, 1.0);  // loop closed
  rig.run(1);
  EXPECT_TRUE(rig.estop.sample().value);
  EXPECT_TRUE(rig.estop.sample().ok());
  rig.run(10);
  EXPECT_FALSE(rig.estop.sample().value);
}

TEST(SimDriver, DisconnectedSensorReachesTheSampleStatus) {
  ServoRig rig("[[events]]\nat_s = 0.005\nsensor = \"pressure_a\"\nfault = \"disconnected\"\n");
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.run(40);
  EXPECT_EQ(rig.pressure_a.sample().status, SampleStatus::ok);
  rig.run(20);
  EXPECT_EQ(rig.pressure_a.sample().status, SampleStatus::disconnected);
  EXPECT_EQ(rig.pressure_b.sample().status, SampleStatus::ok);
  EXPECT_EQ(rig.position.sample().status, SampleStatus::ok);
}

TEST(SimDriver, EncoderJumpOffsetsTheReadingFromThenOn) {
  // Same seed, same commands: the only difference between the two rigs is the jump event.
  ServoRig plain;
  ServoRig jumped("[[events]]\nat_s = 0.005\nencoder_jump_m = 0.01\n"
                  "[[events]]\nat_s = 0.008\nencoder_jump_m = -0.002\n");
  for (auto* rig : {&plain, &jumped}) {
    ASSERT_TRUE(rig->driver->activate().ok());
    rig->enable.set(true);
    rig->opening.set(0.2);
  }
  const auto run_both = [&](int cycles) {
    plain.run(cycles);
    jumped.run(cycles);
  };
  run_both(40);
  EXPECT_EQ(jumped.position.sample().value, plain.position.sample().value);
  run_both(20);  // 6 ms
  EXPECT_NEAR(jumped.position.sample().value - plain.position.sample().value, 0.010, 1e-12);
  EXPECT_TRUE(jumped.position.sample().ok());
  run_both(40);  // 10 ms: the offsets add up
  EXPECT_NEAR(jumped.position.sample().value - plain.position.sample().value, 0.008, 1e-12);
  EXPECT_EQ(jumped.pressure_a.sample().value, plain.pressure_a.sample().value);
}

TEST(SimDriver, StaleEncoderKeepsItsLastValueAndTimestamp) {
  ServoRig rig("[[events]]\nat_s = 0.005\nencoder_stale = true\n"
               "[[events]]\nat_s = 0.010\nencoder_stale = false\n");
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.opening.set(0.3);  // the rod moves, so a frozen value is visible
  rig.run(45);
  const AnalogSample last_fresh = rig.position.sample();
  EXPECT_EQ(last_fresh.timestamp, rig.t - period);
  rig.run(30);  // 7.5 ms: stale since 5 ms
  // The read that brings the rig to 5 ms (the 50th, stamped 4.9 ms) applies the event, so the
  // 49th read's sample is the last fresh one.
  EXPECT_EQ(rig.position.sample().timestamp, Timestamp{4800us});
  EXPECT_GT(rig.position.sample().timestamp, last_fresh.timestamp);
  const AnalogSample frozen = rig.position.sample();
  rig.run(10);
  EXPECT_EQ(rig.position.sample().timestamp, frozen.timestamp);
  EXPECT_EQ(rig.position.sample().value, frozen.value);
  EXPECT_TRUE(rig.position.sample().ok());  // stale is not a status the driver knows: only time tells
  EXPECT_EQ(rig.pressure_a.sample().timestamp, rig.t - period);  // the other channels stay fresh
  rig.run(20);  // 11.5 ms: fresh again, and the rod has moved on meanwhile
  EXPECT_EQ(rig.position.sample().timestamp, rig.t - period);
  EXPECT_GT(rig.position.sample().value, frozen.value);
}

TEST(SimDriver, DriverErrorFailsReadAndWriteUntilCleared) {
  // The plugin's own Driver, without a DriverHandle (which would latch the first error).
  const auto plugin = PluginLoader({HSA_PLUGIN_DIR}).load("sim");
  std::unique_ptr<Driver, void (*)(Driver*)> driver(plugin->descriptor().create(),
                                                    plugin->descriptor().destroy);
  ASSERT_TRUE(driver
                  ->on_configure(toml::parse("timing = \"lockstep\"\n"
                                             "[[events]]\nat_s = 0.001\ndriver_error = true\n"
                                             "[[events]]\nat_s = 0.002\ndriver_error = false\n"))
                  .ok());
  ASSERT_TRUE(driver->on_activate().ok());
  std::vector<ChannelSlot> slots(driver->channels().size());
  const auto cycle = [&](Timestamp t) {
    const IoStatus r = driver->read(t, period, slots);
    const IoStatus w = driver->write(t, period, slots);
    EXPECT_EQ(r, w);
    return r;
  };
  Timestamp t{};
  for (int i = 0; i < 9; ++i, t += period) ASSERT_EQ(cycle(t), IoStatus::ok);
  const ChannelSlot encoder_before = slots[0];
  for (int i = 0; i < 10; ++i, t += period) ASSERT_EQ(cycle(t), IoStatus::error) << i;
  EXPECT_EQ(slots[0].timestamp, encoder_before.timestamp);  // a failed read leaves the slots alone
  EXPECT_EQ(cycle(t), IoStatus::ok);
  EXPECT_EQ(slots[0].timestamp, t);
}

TEST(SimDriver, DriverErrorMovesTheHandleToItsErrorState) {
  ServoRig rig("[[events]]\nat_s = 0.001\ndriver_error = true\n");
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.run(9);
  EXPECT_EQ(rig.driver->read(rig.t, period), IoStatus::error);
  EXPECT_EQ(rig.driver->state(), DriverState::error);
}

// A lost bus is not a lost rig: a recovery with the same settings finds the rod where it was,
// not back at initial_position_m, and the outage, timed on the daemon's clock, fails a recovery
// made before it ends.
TEST(SimDriver, ARecoveryFindsTheRigWhereItWasOnceTheTimedOutageEnds) {
  const std::string settings = "valve = \"servo\"\ntiming = \"lockstep\"\nseed = 3\n"
                               "[[events]]\nat_s = 0.05\ndriver_error = true\ndriver_error_s = 0.02\n";
  ServoRig rig(settings.substr(settings.find("[[events]]")));
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.opening.set(0.5);
  rig.enable.set(true);
  int cycles = 0;
  while (rig.driver->read(rig.t, period) == IoStatus::ok && ++cycles < 1000) {
    ASSERT_EQ(rig.driver->write(rig.t, period), IoStatus::ok);
    rig.t += period;
  }
  ASSERT_EQ(rig.driver->state(), DriverState::error) << "no error after " << cycles << " cycles";
  const double at_error = rig.position.sample().value;
  ASSERT_GT(at_error, 0.150 + 2e-3) << "the rod should have risen at half opening";

  // 10 ms into the 20 ms outage: the recovery configures, but the bus fails again at once.
  rig.t += 10ms;
  ASSERT_TRUE(rig.driver->recover(toml::parse(settings)).ok());
  EXPECT_EQ(rig.driver->read(rig.t, period), IoStatus::error);
  // After it: the same rig, the rod where it was (the amplifier's watchdog closed the valve).
  rig.t += 20ms;
  ASSERT_TRUE(rig.driver->recover(toml::parse(settings)).ok());
  EXPECT_EQ(rig.driver->state(), DriverState::active);
  ASSERT_EQ(rig.driver->read(rig.t, period), IoStatus::ok);
  EXPECT_NEAR(rig.position.sample().value, at_error, 0.5e-3);
  EXPECT_EQ(rig.position.sample().timestamp, rig.t);
}

// Other settings after an error, or a cleanup, build the rig anew.
TEST(SimDriver, ACleanupBuildsTheRigAnew) {
  ServoRig rig;
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.opening.set(0.5);
  rig.enable.set(true);
  rig.run(400);
  ASSERT_GT(rig.position.sample().value, 0.150 + 2e-3);
  ASSERT_TRUE(rig.driver->deactivate().ok());
  ASSERT_TRUE(rig.driver->cleanup().ok());
  ASSERT_TRUE(rig.driver->configure(toml::parse("valve = \"servo\"\ntiming = \"lockstep\"\nseed = 3\n")).ok());
  ASSERT_EQ(rig.driver->read(rig.t, period), IoStatus::ok);
  EXPECT_NEAR(rig.position.sample().value, 0.150, 1e-6);
}

TEST(SimDriver, StallBusyWaitsTheGivenNumberOfReads) {
  // Only a lower bound is checked: a busy-wait cannot end early, whatever the machine's load.
  const auto driver = load_sim("timing = \"lockstep\"\n"
                               "[[events]]\nat_s = 0.001\nstall_us = 2000\nstall_cycles = 3\n");
  Timestamp t{};
  for (int i = 0; i < 9; ++i, t += period) ASSERT_EQ(driver->read(t, period), IoStatus::ok);
  for (int i = 0; i < 3; ++i, t += period) {
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(driver->read(t, period), IoStatus::ok);
    EXPECT_GE(std::chrono::steady_clock::now() - start, 2ms) << "read " << i;
  }
}

TEST(SimDriver, CycleTimingAdvancesByDtInWholeSteps) {
  // An e-stop at 1 ms tells when the rig's clock reaches 1 ms.
  const auto driver = load_sim("timing = \"cycle\"\nstep_s = 1e-4\n"
                               "[[events]]\nat_s = 0.001\nestop = true\n");
  const DigitalInput estop = bind_digital_input("estop", *driver, "estop", {.invert = true});
  Timestamp t{};
  for (int i = 0; i < 3; ++i, t += 250us) ASSERT_EQ(driver->read(t, 250us), IoStatus::ok);
  EXPECT_FALSE(estop.sample().value);  // 750 µs: 7 steps and 50 µs carried over
  ASSERT_EQ(driver->read(t, 250us), IoStatus::ok);
  EXPECT_TRUE(estop.sample().value);  // 1 ms: 10 steps
}

TEST(SimDriver, LockstepIgnoresTheCyclesDt) {
  const auto driver = load_sim("timing = \"lockstep\"\n[[events]]\nat_s = 0.001\nestop = true\n");
  const DigitalInput estop = bind_digital_input("estop", *driver, "estop", {.invert = true});
  for (int i = 0; i < 9; ++i) ASSERT_EQ(driver->read(Timestamp{i * 1s}, 1s), IoStatus::ok);
  EXPECT_FALSE(estop.sample().value);
  ASSERT_EQ(driver->read(10s, 1s), IoStatus::ok);
  EXPECT_TRUE(estop.sample().value);
}

TEST(SimDriver, SameSeedSameTrajectory) {
  ServoRig a;
  ServoRig b;
  for (auto* rig : {&a, &b}) {
    ASSERT_TRUE(rig->driver->activate().ok());
    rig->enable.set(true);
    rig->opening.set(0.2);
    rig->run(500);
  }
  EXPECT_EQ(a.position.sample().value, b.position.sample().value);
  EXPECT_EQ(a.pressure_a.sample().value, b.pressure_a.sample().value);
}

TEST(SimDriver, ReadAndWriteDoNotAllocate) {
  // The counter sees allocations made inside the plugin: create() is a `new` in the library.
  const auto plugin = PluginLoader({HSA_PLUGIN_DIR}).load("sim");
  const long before_create = hsa::test::process_allocations();
  Driver* created = plugin->descriptor().create();
  EXPECT_GT(hsa::test::process_allocations(), before_create);
  plugin->descriptor().destroy(created);

  ServoRig rig("[[events]]\nat_s = 0.01\nsensor = \"encoder\"\nfault = \"stuck\"\n"
               "[[events]]\nat_s = 0.02\nencoder_jump_m = 0.001\nencoder_stale = true\n"
               "[[events]]\nat_s = 0.03\nencoder_stale = false\nstall_us = 1\nstall_cycles = 5\n");
  ASSERT_TRUE(rig.driver->activate().ok());
  rig.enable.set(true);
  rig.opening.set(0.1);
  rig.run(10);
  const long before = hsa::test::process_allocations();
  rig.run(1000);
  rig.driver->make_safe();
  rig.run(10);
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
}

TEST(SimDriver, ConfigureErrorsNameTheKey) {
  const auto message = [](const std::string& settings) -> std::string {
    try {
      (void)load_sim(settings);
    } catch (const PluginError& e) {
      EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
      return e.what();
    }
    ADD_FAILURE() << "configured: " << settings;
    return {};
  };
  EXPECT_THAT(message("valve = \"foo\""),
              HasSubstr("(plugin sim): valve: expected \"servo\" or \"proportional\", "
                        "got \"foo\""));
  EXPECT_THAT(message("timing = 3"), HasSubstr("timing: expected \"cycle\", \"lockstep\" or \"device\""));
  EXPECT_THAT(message("laod_kg = 3"), HasSubstr("laod_kg: unknown key"));
  EXPECT_THAT(message("initial_position_m = 2.0"), HasSubstr("initial_position_m"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\nsensor = \"encoder\""),
              HasSubstr("events[0].sensor: expected events[0].fault beside it, got \"encoder\""));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\nsensor = \"flow\"\nfault = \"stuck\""),
              HasSubstr("events[0].sensor: expected \"encoder\", \"pressure_a\""));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\nstall_us = 100"),
              HasSubstr("events[0].stall_us: expected events[0].stall_cycles beside it, got 100"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\nstall_us = 0\nstall_cycles = 1"),
              HasSubstr("events[0].stall_us: expected an integer in [1, 1000000], got 0"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\nencoder_jump_m = nan"),
              HasSubstr("events[0].encoder_jump_m: expected a finite number, got nan"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\ndriver_error = 1"), HasSubstr("events[0].driver_error"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\ndriver_error = false\ndriver_error_s = 1"),
              HasSubstr("events[0].driver_error_s: expected only beside driver_error = true, got 1"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1\ndriver_error = true\ndriver_error_s = 0"),
              HasSubstr("events[0].driver_error_s: expected a finite number in (0, 86400], got 0"));
  EXPECT_THAT(message("[[events]]\nat_s = 0.1"), HasSubstr("events[0]: expected at least one change beside at_s"));
}

}  // namespace
}  // namespace hsa::io
