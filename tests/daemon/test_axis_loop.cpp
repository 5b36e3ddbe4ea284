// The axis loop on the real sim plugin, loaded through the real loader and stepped in lockstep:
// one driver read, one AxisLoop::cycle, one driver write per simulated 100 µs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <numbers>
#include <optional>
#include <string>
#include <thread>

#include <toml++/toml.h>

#include "control/laws/direct_servo/direct_servo_law.hpp"
#include "control/laws/proportional_cascade/proportional_cascade_law.hpp"
#include "daemon/axis/axis_loop.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/support/counting_allocator.hpp"
#include "tests/support/yield_until.hpp"

namespace hsa::daemon {
namespace {

using namespace std::chrono_literals;
constexpr io::Duration kPeriod = 100us;
constexpr int kCyclesPerSecond = 10'000;

// AxisParams with its law's parameters spelled out, as the tests vary them; built() makes the law
// the configuration would (control/laws/).
struct TestAxis : AxisParams {
  control::CascadeParams cascade;
  std::optional<control::GainBounds> gain_bounds;  // unset: the configuration's default bounds

  [[nodiscard]] AxisParams built() const {
    AxisParams p = *this;
    const control::GainBounds bounds = gain_bounds.value_or(
        control::GainBounds{control::kDefaultGainBoundFactor * cascade.cylinder.kp,
                            control::kDefaultGainBoundFactor * cascade.cylinder.ki});
    if (cascade.drive == control::ValveDrive::direct) {
      p.law = std::make_shared<control::DirectServoLaw>(cascade.cylinder, cascade.valve_ticks_per_cylinder_tick, bounds);
    } else {
      p.law = std::make_shared<control::ProportionalCascadeLaw>(cascade, bounds);
    }
    return p;
  }
};

// Both of control/'s PI laws run a control::Cascade; the tests look into it.
const control::Cascade& cascade_of(const AxisLoop& loop) {
  return dynamic_cast<const control::PiCascadeLaw&>(loop.law()).cascade();
}

// The gains of `params` requested at run time.
void request(AxisLoop& loop, const control::CascadeParams& params) {
  loop.request_gains({.kp = params.cylinder.kp, .ki = params.cylinder.ki});
}

// An axis on a servo-valve rig, as the daemon would configure it.
TestAxis servo_axis() {
  TestAxis p;
  p.name = "x";
  p.bindings.position = {"rig", "encoder", {}};
  p.bindings.pressure_a = {"rig", "pressure_a", {}};
  p.bindings.pressure_b = {"rig", "pressure_b", {}};
  p.bindings.valve_command = {"rig", "opening_cmd", {.low_limit = -1.0, .high_limit = 1.0}};
  p.bindings.valve_enable = {"rig", "valve_enable", {}};
  p.bindings.estop = Binding<io::DigitalInputParams>{"rig", "estop", {.invert = true}};
  p.cascade.drive = control::ValveDrive::direct;
  p.cascade.cylinder.max_setpoint_rate_m_s = 0.1;
  p.safety.setpoint_timeout_ns = 50'000'000;  // 50 ms
  p.area_ratio = 0.77;
  return p;
}

// An axis on a proportional-valve rig: the valve loop closes on the spool LVDT.
TestAxis proportional_axis() {
  TestAxis p = servo_axis();
  p.bindings.spool = Binding<io::AnalogInputParams>{"rig", "spool_lvdt", {}};
  p.bindings.valve_command = {"rig", "current_ref", {.low_limit = 0.0, .high_limit = 3.0}};
  p.cascade.drive = control::ValveDrive::proportional;
  p.cascade.valve = control::simulated_proportional_valve_law();
  p.safe_command = 0.0;  // de-energized: the spring parks the spool in its fail-safe zone
  return p;
}

struct Rig {
  explicit Rig(const std::string& settings = "", const TestAxis& params = servo_axis(),
               const std::string& valve = "servo")
      : driver(io::PluginLoader({HSA_PLUGIN_DIR})
                   .load_driver("rig", "sim",
                                toml::parse("valve = \"" + valve +
                                            "\"\ntiming = \"lockstep\"\nseed = 7\n" + settings))),
        command_channel(params.bindings.valve_command.channel) {
    io::DriverHandle* drivers[] = {driver.get()};
    loop.emplace(params.built(), bind_axis_signals(params.name, params.bindings, drivers));
    if (!driver->activate().ok()) throw std::runtime_error("activate failed");
  }

  // One RT cycle. `stream`: the operator sends the current target again (new seq) this cycle.
  void cycle(ExecutiveInputs executive = {}, bool read = true,
             std::uint64_t tick = AxisLoop::kNextTick) {
    const io::Timestamp now{t};
    if (read) {
      ASSERT_EQ(driver->read(now, kPeriod), io::IoStatus::ok);
      // A driver that keeps handing out the pressure A sample it had (value and timestamp).
      if (frozen_pressure_a) driver->slots()[*driver->find_channel("pressure_a")] = *frozen_pressure_a;
    }
    if (stream) {
      ++op.setpoint.seq;
      op.setpoint.utime = t / 1000;
    }
    loop->cycle(t, op, executive, tick);
    ASSERT_EQ(driver->write(now, kPeriod), io::IoStatus::ok);
    t += kPeriod.count();
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) cycle();
  }
  void command(CommandKind kind, ControlMode mode = ControlMode::position) {
    op.command = {op.command.seq + 1, kind, mode, {}, 0};
    cycle();
  }
  void move_to(double target) {
    op.setpoint.target = target;
    stream = true;
  }
  // Runs until the state leaves ENABLED (or the budget ends); returns the cycles run.
  int run_until_not_enabled(int budget) {
    for (int i = 0; i < budget; ++i) {
      cycle();
      if (tm().state != AxisState::enabled) return i + 1;
    }
    return budget;
  }

  const AxisTelemetry& tm() const { return loop->telemetry(); }
  double slot(const char* channel) const { return driver->slots()[*driver->find_channel(channel)].value; }

  std::unique_ptr<io::DriverHandle> driver;
  std::optional<io::ChannelSlot> frozen_pressure_a;
  std::optional<AxisLoop> loop;
  AxisInputsFromOperator op;
  std::string command_channel;
  std::int64_t t = 0;
  bool stream = false;
};

// The valve is safe: command at the null, amplifier off, and so is what the driver will write.
void expect_valve_safe(const Rig& rig) {
  EXPECT_EQ(rig.tm().command, 0.0);
  EXPECT_FALSE(rig.tm().valve_enabled);
  EXPECT_EQ(rig.slot(rig.command_channel.c_str()), 0.0);
  EXPECT_EQ(rig.slot("valve_enable"), 0.0);
}

void enable(Rig& rig) {
  rig.run(5);
  ASSERT_EQ(rig.tm().state, AxisState::disabled);
  rig.command(CommandKind::enable);
  ASSERT_EQ(rig.tm().state, AxisState::enabled);
}

TEST(AxisLoop, EnableThenMoveTo150mmSettlesWithin01mm) {
  Rig rig("initial_position_m = 0.100\n");
  enable(rig);
  EXPECT_TRUE(rig.tm().valve_enabled);
  EXPECT_EQ(rig.slot("valve_enable"), 1.0);
  rig.move_to(0.150);
  rig.run(kCyclesPerSecond * 2);
  double worst = 0.0;
  for (int i = 0; i < kCyclesPerSecond / 2; ++i) {
    rig.cycle();
    worst = std::max(worst, std::abs(rig.tm().position_m - 0.150));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_FALSE(rig.tm().holding);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::none);
  EXPECT_NEAR(rig.tm().velocity_m_s, 0.0, 2e-3);
  EXPECT_GT(rig.tm().pressure_a_pa, 0.0);
}

TEST(AxisLoop, ProportionalValveAxisMovesTo150mmAndRunsOpenLoop) {
  Rig rig("initial_position_m = 0.100\n", proportional_axis(), "proportional");
  enable(rig);
  rig.move_to(0.150);
  rig.run(kCyclesPerSecond * 2);
  double worst = 0.0;
  for (int i = 0; i < kCyclesPerSecond / 2; ++i) {
    rig.cycle();
    worst = std::max(worst, std::abs(rig.tm().position_m - 0.150));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(rig.tm().command, 0.5);  // a current reference near the valve's null, not 0
  EXPECT_NE(rig.tm().spool_position_m, 0.0);

  rig.command(CommandKind::set_mode, ControlMode::open_loop);
  rig.move_to(0.3);  // 30 % opening: the valve loop drives the spool, the rod extends
  rig.run(kCyclesPerSecond / 10);
  EXPECT_GT(rig.tm().position_m, 0.150 + 5e-3);
  const double spool_reference_m = rig.tm().opening * cascade_of(*rig.loop).params().spool_at_full_opening_m;
  EXPECT_DOUBLE_EQ(spool_reference_m, 0.3 * 1.25e-3);
  // How closely the valve loop tracks is the control module's business; that it drives the
  // spool to the open side is this loop's.
  EXPECT_GT(rig.tm().spool_position_m, 0.5 * spool_reference_m);
  rig.command(CommandKind::disable);
  expect_valve_safe(rig);
}

TEST(AxisLoop, CommandIsSafeUntilEnabled) {
  Rig rig;
  rig.move_to(0.200);
  rig.run(100);
  EXPECT_EQ(rig.tm().state, AxisState::disabled);
  expect_valve_safe(rig);
}

TEST(AxisLoop, EstopEventGivesEstopWithTheValveSafeInThatCycle) {
  Rig rig("[[events]]\nat_s = 0.3\nestop = true\n[[events]]\nat_s = 0.4\nestop = false\n");
  enable(rig);
  rig.move_to(0.160);
  const int cycles = rig.run_until_not_enabled(kCyclesPerSecond);
  // Lockstep: the rig's clock counts reads, not wall time, so this count is exact on any
  // machine. It reaches 0.3 s on read number 3000; enable() took 6 of them.
  EXPECT_EQ(cycles, 3000 - 6);
  EXPECT_EQ(rig.tm().state, AxisState::estop);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::estop);
  expect_valve_safe(rig);

  rig.command(CommandKind::reset);
  EXPECT_EQ(rig.tm().last_command.refusal, Refusal::estop_pressed);
  rig.run(1000);  // released at 0.4 s
  rig.command(CommandKind::reset);
  EXPECT_EQ(rig.tm().state, AxisState::disabled);
  rig.command(CommandKind::enable);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_TRUE(rig.tm().valve_enabled);
}

TEST(AxisLoop, DisconnectedSensorGivesFaultAndResetWaitsForIt) {
  Rig rig("[[events]]\nat_s = 0.2\nsensor = \"pressure_a\"\nfault = \"disconnected\"\n"
          "[[events]]\nat_s = 0.3\nsensor = \"pressure_a\"\nfault = \"none\"\n");
  enable(rig);
  rig.move_to(0.150);
  const int cycles = rig.run_until_not_enabled(kCyclesPerSecond);
  EXPECT_LT(cycles, 2000);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::sensor_not_ok);
  EXPECT_EQ(rig.tm().fault.signal, FaultSignal::pressure_a);
  EXPECT_EQ(describe(rig.tm().fault), "pressure A sample disconnected");
  expect_valve_safe(rig);

  rig.command(CommandKind::enable);
  EXPECT_EQ(rig.tm().last_command.refusal, Refusal::reset_first);
  rig.command(CommandKind::reset);
  EXPECT_EQ(rig.tm().last_command.refusal, Refusal::cause_present);
  EXPECT_EQ(rig.tm().last_command.blocking, FaultReason::sensor_not_ok);
  rig.run(1000);  // reconnected at 0.3 s
  rig.command(CommandKind::reset);
  EXPECT_EQ(rig.tm().state, AxisState::disabled);
}

TEST(AxisLoop, SupplyLostGivesFollowingError) {
  TestAxis p = servo_axis();
  p.safety.saturation_cycles = 100'000;  // so that the following error is what trips
  Rig rig("[[events]]\nat_s = 0.2\nsupply_lost = true\n", p);
  enable(rig);
  rig.move_to(0.150);
  rig.run(3000);
  ASSERT_EQ(rig.tm().state, AxisState::enabled);
  rig.move_to(0.250);
  rig.run_until_not_enabled(kCyclesPerSecond);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::following_error);
  EXPECT_GT(rig.tm().fault.value, p.safety.following_error_max_m);
  expect_valve_safe(rig);
}

TEST(AxisLoop, HeavyLoadGivesOverPressure) {
  TestAxis p = servo_axis();
  p.safety.pressure_max_pa = 20e5;
  Rig rig("[[events]]\nat_s = 0.2\nload_kg = 150\n", p);
  enable(rig);
  rig.move_to(0.150);
  rig.run(1000);
  ASSERT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_LT(rig.tm().pressure_a_pa, 20e5);
  rig.run_until_not_enabled(kCyclesPerSecond);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::over_pressure);
  EXPECT_EQ(rig.tm().fault.signal, FaultSignal::pressure_a);
  EXPECT_GT(rig.tm().fault.value, 20e5);
  expect_valve_safe(rig);
}

TEST(AxisLoop, LongSaturatedMoveGivesCurrentSaturated) {
  TestAxis p = servo_axis();
  p.cascade.cylinder.max_setpoint_rate_m_s = std::numeric_limits<double>::infinity();
  p.safety.following_error_max_m = 0.5;  // so that the saturation is what trips
  p.safety.saturation_cycles = 1000;     // 0.1 s
  Rig rig("initial_position_m = 0.050\n", p);
  enable(rig);
  rig.move_to(0.250);
  const int cycles = rig.run_until_not_enabled(kCyclesPerSecond);
  EXPECT_GE(cycles, 1000);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::current_saturated);
  expect_valve_safe(rig);
}

// A 2 Hz, 7 mm sine around 150 mm (peak speed 88 mm/s, inside the 0.1 m/s rate limit), sent with its velocity as feed-forward; returns the largest
// |following error| over the second of its two seconds (after the start-up transient).
double sine_following_error(double velocity_feedforward) {
  TestAxis p = servo_axis();
  p.cascade.cylinder.velocity_feedforward = velocity_feedforward;
  Rig rig("", p);
  enable(rig);
  rig.move_to(0.150);
  rig.run(kCyclesPerSecond / 2);
  const double w = 2.0 * std::numbers::pi * 2.0, amplitude = 0.007;
  double worst = 0.0;
  for (int i = 0; i < 2 * kCyclesPerSecond; ++i) {
    const double t = static_cast<double>(i) / kCyclesPerSecond;
    rig.op.setpoint.target = 0.150 + amplitude * std::sin(w * t);
    rig.op.setpoint.velocity_m_s = amplitude * w * std::cos(w * t);
    rig.cycle();
    if (i >= kCyclesPerSecond) worst = std::max(worst, std::abs(rig.tm().following_error_m));
  }
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  return worst;
}

TEST(AxisLoop, VelocityFeedforwardReducesTheFollowingErrorOnASine) {
  const double without = sine_following_error(0.0);  // the default: the velocity is ignored
  // About 1 / (rod speed at full opening) of the sim rig's servo-valve cylinder.
  const double with = sine_following_error(4.0);
  EXPECT_GT(without, 1e-3);  // a PI alone lags a 2 Hz sine by millimetres
  EXPECT_LT(with, 0.5 * without) << "without " << without << " m, with " << with << " m";
}

TEST(AxisLoop, OpenLoopPastTheSoftLimitGivesSoftLimit) {
  TestAxis p = servo_axis();
  p.safety.soft_limit_high_m = 0.170;
  Rig rig("", p);
  enable(rig);
  rig.command(CommandKind::set_mode, ControlMode::open_loop);
  EXPECT_EQ(rig.tm().mode, ControlMode::open_loop);
  rig.move_to(0.2);  // opening 0.2 in open loop
  rig.cycle();
  EXPECT_DOUBLE_EQ(rig.tm().command, 0.2);
  rig.run_until_not_enabled(kCyclesPerSecond);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::soft_limit);
  EXPECT_GT(rig.tm().fault.value, 0.170);
  expect_valve_safe(rig);

  // The rod stopped past the limit. Reset, position mode, enable: the axis drives it back in and
  // then follows a move as before.
  rig.stream = false;
  rig.run(1000);
  ASSERT_GT(rig.tm().position_m, 0.170);
  rig.command(CommandKind::reset);
  ASSERT_EQ(rig.tm().state, AxisState::disabled);
  rig.command(CommandKind::set_mode, ControlMode::position);
  rig.command(CommandKind::enable);
  ASSERT_EQ(rig.tm().state, AxisState::enabled);
  rig.run(kCyclesPerSecond / 2);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  // Held where it was clamped to: the setpoint band's edge, kSoftLimitSetpointMarginM inside.
  EXPECT_NEAR(rig.tm().position_m, 0.170 - kSoftLimitSetpointMarginM, 0.5e-3);
  rig.move_to(0.150);
  rig.run(kCyclesPerSecond * 2);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_NEAR(rig.tm().position_m, 0.150, 0.1e-3);
  EXPECT_TRUE(rig.loop->supervisor().soft_limits_armed());
}

TEST(AxisLoop, ExecutiveInputsGiveDriverErrorAndOverrunFaults) {
  for (const bool driver_error : {true, false}) {
    Rig rig;
    enable(rig);
    rig.move_to(0.150);
    rig.run(100);
    ExecutiveInputs ex;
    ex.driver_error = driver_error;
    ex.overrun_streak = driver_error ? 0 : 10;
    rig.cycle(ex);
    EXPECT_EQ(rig.tm().state, AxisState::fault);
    EXPECT_EQ(rig.tm().fault.reason,
              driver_error ? FaultReason::driver_error : FaultReason::rt_overruns);
    expect_valve_safe(rig);
  }
}

TEST(AxisLoop, EncoderWithoutNewSamplesGoesStale) {
  Rig rig;
  enable(rig);
  rig.move_to(0.150);
  rig.run(100);
  // The executive keeps cycling but the driver delivers nothing new (a stalled bus thread): the
  // axis faults on the cycle that completes the default count (safety_defaults.hpp).
  const std::uint32_t stale_cycles = SupervisorParams{}.encoder_stale_cycles;
  ASSERT_GT(stale_cycles, 1u);
  for (std::uint32_t i = 0; i + 1 < stale_cycles; ++i) rig.cycle({}, /*read=*/false);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  rig.cycle({}, false);
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::encoder_stale);
  expect_valve_safe(rig);
}

// A driver in error is not read (DriverHandle stops calling it): its inputs keep their last values,
// and the age that telemetry and status carry with them grows by a period every cycle, live up to
// input_stale_s and stale past it, while the value itself stays what it was.
TEST(AxisLoop, InputsNoLongerReadAgeEveryCycleAndTurnStalePastInputStale) {
  Rig rig;
  enable(rig);
  rig.move_to(0.150);
  rig.run(100);
  const auto input = [&](FaultSignal which) { return rig.tm().inputs[static_cast<std::size_t>(which) - 1]; };
  const FaultSignal bound[] = {FaultSignal::position, FaultSignal::pressure_a, FaultSignal::pressure_b,
                               FaultSignal::estop};
  for (const FaultSignal s : bound) {  // the sim plugin stamps its samples with the read's time
    EXPECT_EQ(input(s).age_ns, 0) << to_string(s);
    EXPECT_FALSE(input(s).stale) << to_string(s);
  }
  EXPECT_EQ(input(FaultSignal::spool).age_ns, -1);  // a servo-valve axis has none
  const double position = rig.tm().position_m;

  ExecutiveInputs driver_error;
  driver_error.driver_error = true;
  const std::int64_t stale_ns = servo_axis().safety.input_stale_ns;
  const std::int64_t live_cycles = stale_ns / kPeriod.count();
  rig.cycle(driver_error, /*read=*/false);
  EXPECT_EQ(input(FaultSignal::position).age_ns, kPeriod.count());
  for (std::int64_t i = 1; i < live_cycles; ++i) rig.cycle(driver_error, false);
  for (const FaultSignal s : bound) {
    EXPECT_EQ(input(s).age_ns, stale_ns) << to_string(s);
    EXPECT_FALSE(input(s).stale) << to_string(s);
  }
  rig.cycle(driver_error, false);
  for (const FaultSignal s : bound) {
    EXPECT_EQ(input(s).age_ns, stale_ns + kPeriod.count()) << to_string(s);
    EXPECT_TRUE(input(s).stale) << to_string(s);
  }
  EXPECT_EQ(rig.tm().position_m, position);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::driver_error);
}

// The loop stalls 50 ms between two cycles (the lockstep clock simply jumps): the axis faults with
// blind_time in the cycle after the gap, the gap as its value, the valve safe in that cycle, and
// no overrun streak is needed for it.
TEST(AxisLoop, FiftyMillisecondsWithoutACycleGiveBlindTime) {
  Rig rig;
  enable(rig);
  rig.move_to(0.150);
  rig.run(100);
  ASSERT_EQ(rig.tm().state, AxisState::enabled);
  rig.t += 50'000'000;
  rig.cycle();
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::blind_time);
  EXPECT_DOUBLE_EQ(rig.tm().fault.value, (50'000'000 + kPeriod.count()) * 1e-9);
  EXPECT_DOUBLE_EQ(rig.tm().fault.limit, 0.005);
  expect_valve_safe(rig);
  // The next cycles are on time: a reset goes through and the axis can be enabled again.
  rig.command(CommandKind::reset);
  EXPECT_EQ(rig.tm().state, AxisState::disabled);
  rig.command(CommandKind::enable);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
}

// Pressure A keeps its last sample, timestamp and all, while everything else is fresh: after
// input_stale_s (0.1 s = 1000 cycles here) without a new timestamp the axis faults naming it.
TEST(AxisLoop, APressureWhoseTimestampStopsFaultsNamingIt) {
  Rig rig;
  enable(rig);
  rig.move_to(0.150);
  rig.run(100);
  rig.frozen_pressure_a = rig.driver->slots()[*rig.driver->find_channel("pressure_a")];
  const int cycles = rig.run_until_not_enabled(2000);
  EXPECT_GE(cycles, 1000);  // not before its bound ...
  EXPECT_LE(cycles, 1001);  // ... and in the first cycle past it
  EXPECT_EQ(rig.tm().state, AxisState::fault);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::sensor_not_ok);
  EXPECT_EQ(rig.tm().fault.signal, FaultSignal::pressure_a);
  EXPECT_EQ(rig.tm().fault.status, io::SampleStatus::stale);
  EXPECT_EQ(describe(rig.tm().fault).rfind("pressure A stale: no new sample for 100.", 0), 0u)
      << describe(rig.tm().fault);
  expect_valve_safe(rig);
}

// The shutdown's last cycle (the executive stopped a while before it) only disables: the pause
// is not blind time, and the final status says DISABLED, not FAULT.
TEST(AxisLoop, TheFinalCycleAfterTheExecutiveStoppedIsNotBlindTime) {
  Rig rig;
  enable(rig);
  rig.move_to(0.150);
  rig.run(100);
  rig.t += 200'000'000;
  rig.op.command = {rig.op.command.seq + 1, CommandKind::disable, ControlMode::position, {}, 0};
  ExecutiveInputs last;
  last.final_cycle = true;
  rig.cycle(last);
  EXPECT_EQ(rig.tm().state, AxisState::disabled);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::none);
  expect_valve_safe(rig);
}

// A NaN reaching the loop output (here through the velocity feed-forward of a setpoint, which the
// LCM side would have rejected) faults in that very cycle: the valve command slot holds the safe
// value and the enable slot 0, never the NaN.
TEST(AxisLoop, NonFiniteCommandFaultsInThatCycleWithTheValveSafe) {
  for (const bool proportional : {false, true}) {
    SCOPED_TRACE(proportional ? "proportional" : "servo");
    TestAxis p = proportional ? proportional_axis() : servo_axis();
    p.cascade.cylinder.velocity_feedforward = 5.0;
    Rig rig("", p, proportional ? "proportional" : "servo");
    enable(rig);
    rig.move_to(0.150);
    rig.run(100);
    ASSERT_EQ(rig.tm().state, AxisState::enabled);
    ASSERT_TRUE(rig.tm().valve_enabled);
    rig.op.setpoint.velocity_m_s = std::numeric_limits<double>::quiet_NaN();
    // The PI runs on one tick in ten: within ten cycles the NaN reaches the command.
    const int cycles = rig.run_until_not_enabled(10);
    EXPECT_LE(cycles, 10);
    EXPECT_EQ(rig.tm().state, AxisState::fault);
    EXPECT_EQ(rig.tm().fault.reason, FaultReason::control_output);
    EXPECT_TRUE(std::isnan(rig.tm().fault.value));
    EXPECT_EQ(rig.tm().command, p.safe_command);
    EXPECT_FALSE(rig.tm().valve_enabled);
    EXPECT_EQ(rig.slot(rig.command_channel.c_str()), p.safe_command);
    EXPECT_EQ(rig.slot("valve_enable"), 0.0);
    // Reset and enable again: the loops restart from the measured state, finite.
    rig.op.setpoint.velocity_m_s = 0.0;
    rig.command(CommandKind::reset);
    rig.command(CommandKind::enable);
    rig.run(20);
    EXPECT_EQ(rig.tm().state, AxisState::enabled);
    EXPECT_TRUE(std::isfinite(rig.tm().command));
  }
}

// Skipped base ticks (the executive drops the periods it overran) advance the loops by the time
// that passed: the setpoint ramp of a run that skipped 39 ticks is where the ramp of a run that
// ticked all 40 is (4 PI periods either way, up to the rounding of 4 sums).
TEST(AxisLoop, SkippedTicksAdvanceTheRampByTheElapsedTime) {
  Rig every, skipping;
  for (Rig* r : {&every, &skipping}) {
    enable(*r);
    r->move_to(0.250);
    r->run(100);
  }
  ASSERT_EQ(every.loop->law().limited_setpoint_m(), skipping.loop->law().limited_setpoint_m());
  const double before = every.loop->law().limited_setpoint_m();
  const std::uint64_t tick = every.tm().cycle;  // kNextTick counts from 0: cycles so far
  for (int i = 0; i < 40; ++i) every.cycle({}, true, tick + static_cast<std::uint64_t>(i));
  skipping.t += 39 * kPeriod.count();
  skipping.cycle({}, true, tick + 39);
  // 0.1 m/s × 1 ms per PI period: 0.4 mm in 4 periods.
  EXPECT_NEAR(every.loop->law().limited_setpoint_m() - before, 4 * 0.1 * 1e-3, 1e-12);
  EXPECT_NEAR(skipping.loop->law().limited_setpoint_m(), every.loop->law().limited_setpoint_m(), 1e-15);
}

TEST(AxisLoop, SetpointSilenceHoldsPosition) {
  Rig rig;
  enable(rig);
  rig.move_to(0.160);
  rig.run(kCyclesPerSecond / 2);
  EXPECT_FALSE(rig.tm().holding);
  rig.stream = false;  // the operator goes quiet
  rig.run(499);        // 49.9 ms: within the 50 ms timeout
  EXPECT_FALSE(rig.tm().holding);
  rig.run(2);
  EXPECT_TRUE(rig.tm().holding);
  const double held = rig.tm().setpoint;
  rig.run(kCyclesPerSecond / 2);
  EXPECT_TRUE(rig.tm().holding);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::none);
  EXPECT_DOUBLE_EQ(rig.tm().setpoint, held);
  EXPECT_NEAR(rig.tm().position_m, held, 2e-4);
  rig.move_to(0.170);
  rig.cycle();
  EXPECT_FALSE(rig.tm().holding);
}

TEST(AxisLoop, GainChangeAppliesAtTheNextCycleBoundaryBumplessly) {
  Rig rig;
  enable(rig);
  rig.move_to(0.170);
  rig.run(500);  // moving: the PI output is well away from zero
  control::CascadeParams gains = cascade_of(*rig.loop).params();
  gains.cylinder.kp = 40.0;
  request(*rig.loop, gains);
  EXPECT_EQ(cascade_of(*rig.loop).params().cylinder.kp, 85.0);  // not before the boundary
  EXPECT_EQ(rig.tm().param_changes_applied, 0u);
  const double opening_before = rig.tm().opening;
  rig.cycle();
  EXPECT_EQ(cascade_of(*rig.loop).params().cylinder.kp, 40.0);
  EXPECT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_NEAR(rig.tm().opening, opening_before, 0.02);  // no step at the change
  rig.run(kCyclesPerSecond * 2);
  EXPECT_NEAR(rig.tm().position_m, 0.170, 1e-4);  // still converges with the new gain
}

// The largest step of the valve command and of the opening between consecutive cycles.
struct CycleSteps {
  double command = 0.0;
  double opening = 0.0;
};

CycleSteps steps_over(Rig& rig, int cycles) {
  CycleSteps steps;
  for (int i = 0; i < cycles; ++i) {
    const double command = rig.tm().command, opening = rig.tm().opening;
    rig.cycle();
    steps.command = std::max(steps.command, std::abs(rig.tm().command - command));
    steps.opening = std::max(steps.opening, std::abs(rig.tm().opening - opening));
  }
  return steps;
}

// A gain change while the proportional-valve axis holds 150 mm: the current reference and the
// opening move across the change (and over the cylinder-loop ticks after it, which run the new
// PI) by no more than they moved between any two cycles of the 100 before it.
TEST(AxisLoop, ProportionalValveGainChangeWhileHoldingKeepsTheCurrentContinuous) {
  Rig rig("initial_position_m = 0.100\n", proportional_axis(), "proportional");
  enable(rig);
  rig.move_to(0.150);
  rig.run(kCyclesPerSecond * 2);
  ASSERT_NEAR(rig.tm().position_m, 0.150, 1e-4);
  const CycleSteps before = steps_over(rig, 100);
  ASSERT_GT(before.command, 0.0);  // the valve loop was working: the bound is not zero
  control::CascadeParams gains = cascade_of(*rig.loop).params();
  gains.cylinder.kp = 2.0 * 85.0;  // the default bound: twice the configured gains
  gains.cylinder.ki = 0.5 * 460.0;
  request(*rig.loop, gains);
  // The valve loop as it stands before the change, to be carried on by hand.
  control::StatePredictor predictor = cascade_of(*rig.loop).predictor();
  control::ValveLaw law = cascade_of(*rig.loop).valve();
  const CycleSteps at_change = steps_over(rig, 1);
  ASSERT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_EQ(cascade_of(*rig.loop).params().cylinder.kp, 170.0);
  // The change kept the predictor and the valve law: one more step of each from their state
  // before gives exactly this cycle's predictor state and current.
  const control::PredictorOutput predicted = predictor.update(rig.tm().spool_position_m);
  EXPECT_EQ(cascade_of(*rig.loop).predictor().state(), predictor.state());
  const double spool_reference_m = rig.tm().opening * cascade_of(*rig.loop).params().spool_at_full_opening_m;
  EXPECT_EQ(law.update(spool_reference_m, predicted), rig.tm().command);
  const CycleSteps after = steps_over(rig, 10);  // one whole cylinder-loop period with the new PI
  std::printf("proportional axis holding 150 mm: largest current step %.4g A before the change, "
              "%.4g A at it, %.4g A in the 10 cycles after\n",
              before.command, at_change.command, after.command);
  EXPECT_LE(at_change.command, before.command);
  EXPECT_LE(after.command, before.command);
  EXPECT_LE(at_change.opening, std::max(before.opening, 1e-12));
  EXPECT_LE(after.opening, std::max(before.opening, 1e-12));
  rig.run(kCyclesPerSecond);
  EXPECT_NEAR(rig.tm().position_m, 0.150, 1e-4);  // still holds with the new gains
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
}

// The same on the servo-valve (direct drive) while the rod moves.
TEST(AxisLoop, DirectDriveGainChangeWhileMovingKeepsTheOpeningContinuous) {
  Rig rig;
  enable(rig);
  rig.move_to(0.170);
  rig.run(300);
  const CycleSteps before = steps_over(rig, 100);
  ASSERT_GT(before.opening, 0.0);
  control::CascadeParams gains = cascade_of(*rig.loop).params();
  gains.cylinder.kp = 40.0;
  request(*rig.loop, gains);
  const CycleSteps after = steps_over(rig, 11);
  ASSERT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_LE(after.opening, before.opening);
  EXPECT_LE(after.command, before.command);
}

// Gains outside the axis's bounds or not finite: refused on the caller's thread with the reason,
// and nothing reaches the loop. (A request carries only the law's runtime gains, so nothing else
// of the loops can be asked to change.)
TEST(AxisLoop, GainRequestsOutsideTheBoundsAreRefusedWithTheReason) {
  Rig rig;
  EXPECT_EQ(rig.loop->law().gain_bounds().max_kp, 170.0);  // default: twice the configured gains
  EXPECT_EQ(rig.loop->law().gain_bounds().max_ki, 920.0);
  const control::CascadeParams ok = cascade_of(*rig.loop).params();
  const auto refusal = [&](const std::function<void(control::CascadeParams&)>& change) {
    control::CascadeParams p = ok;
    change(p);
    try {
      request(*rig.loop, p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  using ::testing::HasSubstr;
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.kp = 170.5; }), HasSubstr("kp 170.5 is outside (0, max_kp 170]"));
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.kp = 0.0; }), HasSubstr("kp 0 is outside (0, max_kp 170]"));
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.ki = 921.0; }), HasSubstr("ki 921 is outside [0, max_ki 920]"));
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.ki = -1.0; }), HasSubstr("ki -1 is outside"));
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.kp = std::nan(""); }), HasSubstr("finite"));
  EXPECT_THAT(refusal([](auto& p) { p.cylinder.ki = std::numeric_limits<double>::infinity(); }), HasSubstr("finite"));
  rig.run(2);
  EXPECT_EQ(rig.tm().param_changes_applied, 0u);
  EXPECT_EQ(cascade_of(*rig.loop).params(), ok);
  // At the bounds themselves: accepted.
  EXPECT_EQ(refusal([](auto& p) {
              p.cylinder.kp = 170.0;
              p.cylinder.ki = 0.0;
            }),
            "accepted");
  rig.cycle();
  EXPECT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_EQ(rig.tm().kp, 170.0);
  EXPECT_EQ(rig.tm().ki, 0.0);
}

TEST(AxisLoop, ConfiguredGainsOutsideTheirBoundsAreRefused) {
  TestAxis p = servo_axis();
  p.gain_bounds = control::GainBounds{.max_kp = 50.0, .max_ki = 1000.0};  // below kp = 85
  EXPECT_THROW(Rig("", p), std::invalid_argument);
  p.gain_bounds = control::GainBounds{.max_kp = std::numeric_limits<double>::infinity(), .max_ki = 1000.0};
  EXPECT_THROW(Rig("", p), std::invalid_argument);
  p.gain_bounds = control::GainBounds{.max_kp = 85.0, .max_ki = 460.0};  // the gains themselves: no room
  EXPECT_NO_THROW(Rig("", p));
}

TEST(AxisLoop, GainRequestsTheLawRefusesAreRefusedOnTheCallersThread) {
  Rig rig;
  control::CascadeParams bad = cascade_of(*rig.loop).params();
  bad.cylinder.kp = -1.0;
  EXPECT_THROW(request(*rig.loop, bad), std::invalid_argument);
  rig.cycle();
  EXPECT_EQ(rig.tm().param_changes_applied, 0u);
}

// The operator thread publishes gains while the RT thread cycles. Every 100 requests the writer
// waits (bounded) until a cycle has applied a change it made since the last checkpoint: on a
// loaded machine, or pinned to one CPU, it could otherwise finish before the first cycle ran, and
// nothing would overlap.
TEST(AxisLoop, ParamsPublishedFromAnotherThreadArriveWhole) {
  constexpr int kRequests = 2000;
  constexpr int kCheckpoint = 100;
  TestAxis params = servo_axis();
  params.gain_bounds = control::GainBounds{.max_kp = 100.0, .max_ki = 1000.0};  // room for the writer's gains
  Rig rig("", params);
  enable(rig);
  rig.move_to(0.150);
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> applied{0};  // the RT side's count, mirrored for the writer
  std::atomic<int> checkpoints_missed{0};
  std::thread writer([&] {
    control::CascadeParams p = cascade_of(*rig.loop).params();
    std::uint64_t applied_at_checkpoint = 0;
    for (int i = 1; i <= kRequests; ++i) {
      // kp and ki always change together: a torn handoff would break the pairing.
      p.cylinder.kp = 50.0 + (i % 50);
      p.cylinder.ki = 10.0 * p.cylinder.kp;
      request(*rig.loop, p);
      if (i % kCheckpoint == 0) {
        if (!hsa::test::yield_until([&] { return applied.load() > applied_at_checkpoint; })) ++checkpoints_missed;
        applied_at_checkpoint = applied.load();
      }
    }
    done = true;
  });
  bool torn = false;
  while (!done) {
    rig.cycle();
    const control::PiParams& pi = cascade_of(*rig.loop).params().cylinder;
    torn = torn || (rig.tm().param_changes_applied > 0 && pi.ki != 10.0 * pi.kp);
    applied.store(rig.tm().param_changes_applied);
  }
  writer.join();
  rig.cycle();
  EXPECT_FALSE(torn);
  EXPECT_EQ(cascade_of(*rig.loop).params().cylinder.kp, 50.0 + (kRequests % 50));
  EXPECT_EQ(checkpoints_missed.load(), 0);
  // Each checkpoint needed a change applied by a cycle that ran while the writer did.
  EXPECT_GE(rig.tm().param_changes_applied, static_cast<std::uint64_t>(kRequests / kCheckpoint));
}

TEST(AxisLoop, CycleDoesNotAllocateInSteadyState) {
  Rig rig;
  enable(rig);
  rig.move_to(0.160);
  rig.run(1000);
  control::CascadeParams gains = cascade_of(*rig.loop).params();
  gains.cylinder.kp = 60.0;
  request(*rig.loop, gains);  // the request allocates on its thread; applying must not

  const long before = hsa::test::process_allocations();
  rig.run(5000);
  rig.command(CommandKind::set_mode, ControlMode::open_loop);
  rig.move_to(0.05);
  rig.run(1000);
  rig.command(CommandKind::set_mode, ControlMode::position);
  rig.move_to(0.150);
  rig.run(1000);
  ExecutiveInputs ex;
  ex.driver_error = true;
  rig.cycle(ex);  // a fault and its reset are steady-state events too
  rig.command(CommandKind::reset);
  rig.command(CommandKind::enable);
  rig.run(1000);
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
  EXPECT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_EQ(rig.tm().state, AxisState::enabled);
  EXPECT_EQ(rig.loop->supervisor().faults_tripped(), 1u);
}

// An excitation (excite) at 150 mm: ±1 mm PRMS, a level every 50 ms, for `duration_s`.
void excite(Rig& rig, double duration_s = 0.5, double kp_per_m = 200.0) {
  rig.stream = false;
  rig.op.command = AxisCommand{};
  rig.op.command.seq = 1000 + rig.op.command.seq;
  rig.op.command.kind = CommandKind::excite;
  rig.op.command.excite = {.working_point_m = 0.150,
                           .kind = control::ExcitationKind::prms,
                           .amplitude_m = 1e-3,
                           .switching_time_s = 0.05,
                           .levels = 5,
                           .seed = 3,
                           .duration_s = duration_s,
                           .kp_per_m = kp_per_m};
  rig.cycle();
}

TEST(AxisLoop, AnExcitationRunsPControlOnItsSetpointThenGivesThePiGainsBackBumplessly) {
  Rig rig;
  enable(rig);
  rig.run(1000);  // holding 150 mm with the PI
  excite(rig);
  const control::PiController& pi = cascade_of(*rig.loop).cylinder();
  double lowest = 1.0, highest = -1.0, last_opening = 0.0;
  int cycles = 1;
  for (; rig.tm().exciting; ++cycles) {
    ASSERT_EQ(rig.tm().state, AxisState::enabled);
    ASSERT_EQ(rig.tm().kp, 200.0);
    ASSERT_EQ(rig.tm().ki, 0.0);
    // P control, the integral off: the opening is kp times the error of the loop's last sample.
    ASSERT_EQ(pi.integral(), 0.0);
    ASSERT_NEAR(pi.output(), 200.0 * pi.error(), 1e-12);
    // The record's setpoint is the one the error is taken from.
    ASSERT_EQ(rig.tm().setpoint, rig.loop->law().limited_setpoint_m());
    lowest = std::min(lowest, rig.tm().position_m);
    highest = std::max(highest, rig.tm().position_m);
    last_opening = rig.tm().opening;
    rig.cycle();
    ASSERT_LT(cycles, 6000);
  }
  EXPECT_NEAR(cycles, 5000, 1);  // its 0.5 s, to the base tick
  EXPECT_GT(highest - lowest, 1e-3);  // the rod followed the levels
  EXPECT_LT(highest - lowest, 3e-3);
  // Over: the PI's gains, bumpless (the opening continues), holding the working point.
  EXPECT_EQ(rig.tm().kp, 85.0);
  EXPECT_EQ(rig.tm().ki, 460.0);
  EXPECT_NEAR(rig.tm().opening, last_opening, 0.02);
  EXPECT_TRUE(rig.tm().holding);
  rig.run(kCyclesPerSecond);
  EXPECT_NEAR(rig.tm().position_m, 0.150, 1e-4);
  EXPECT_EQ(rig.tm().fault.reason, FaultReason::none);
}

TEST(AxisLoop, GainsSetDuringAnExcitationEndItAndApply) {
  Rig rig;
  enable(rig);
  excite(rig, 5.0);
  rig.run(100);
  ASSERT_TRUE(rig.tm().exciting);
  rig.loop->request_gains({.kp = 60.0, .ki = 300.0});
  rig.cycle();
  EXPECT_FALSE(rig.tm().exciting);
  EXPECT_EQ(rig.tm().kp, 60.0);
  EXPECT_EQ(rig.tm().ki, 300.0);
  EXPECT_EQ(rig.tm().param_changes_applied, 1u);
}

TEST(AxisLoop, ADisableEndsAnExcitationAndTheGainsComeBack) {
  Rig rig;
  enable(rig);
  excite(rig, 5.0);
  rig.run(100);
  rig.command(CommandKind::disable);
  EXPECT_FALSE(rig.tm().exciting);
  EXPECT_EQ(rig.tm().kp, 85.0);
  EXPECT_EQ(rig.tm().ki, 460.0);
  expect_valve_safe(rig);
}

TEST(AxisLoop, ExcitationsDoNotAllocate) {
  Rig rig;
  enable(rig);
  rig.run(1000);
  long cycles_allocated = 0;  // what the cycles allocated, not the gain request's own thread work
  long before = hsa::test::process_allocations();
  excite(rig, 0.3);
  rig.run(3500);  // the whole run and its end
  excite(rig, 5.0);
  rig.run(100);
  excite(rig, 5.0);  // one replacing another
  rig.run(100);
  cycles_allocated += hsa::test::process_allocations() - before;
  rig.loop->request_gains({.kp = 70.0, .ki = 400.0});  // allocates on its thread; applying must not
  before = hsa::test::process_allocations();
  rig.run(1);  // the gains arrive: they end it
  EXPECT_FALSE(rig.tm().exciting);
  rig.command(CommandKind::set_mode, ControlMode::position);
  excite(rig, 5.0);
  rig.run(100);
  rig.command(CommandKind::disable);
  cycles_allocated += hsa::test::process_allocations() - before;
  EXPECT_EQ(cycles_allocated, 0);
  EXPECT_EQ(rig.tm().param_changes_applied, 1u);
  EXPECT_EQ(rig.tm().kp, 70.0);
  EXPECT_EQ(rig.loop->supervisor().faults_tripped(), 0u);
}

TEST(AxisLoop, BindingNamesTheMissingDriverAndAProportionalDriveNeedsASpool) {
  const auto driver = io::PluginLoader({HSA_PLUGIN_DIR})
                          .load_driver("rig", "sim", toml::parse("valve = \"proportional\"\n"));
  io::DriverHandle* drivers[] = {driver.get()};
  TestAxis p = servo_axis();
  p.bindings.valve_command = {"rig", "current_ref", {}};
  p.bindings.pressure_b.driver = "bus";
  try {
    (void)bind_axis_signals("x", p.bindings, drivers);
    ADD_FAILURE() << "bound";
  } catch (const io::BindingError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("signal 'x.pressure_b': no driver named 'bus'"));
  }
  p.bindings.pressure_b.driver = "rig";
  p.cascade.drive = control::ValveDrive::proportional;
  EXPECT_THROW(AxisLoop(p.built(), bind_axis_signals("x", p.bindings, drivers)), std::invalid_argument);
  p.bindings.spool = Binding<io::AnalogInputParams>{"rig", "spool_lvdt", {}};
  EXPECT_NO_THROW(AxisLoop(p.built(), bind_axis_signals("x", p.bindings, drivers)));
}

}  // namespace
}  // namespace hsa::daemon
