// MOVE_TO on the simulated rig with the example configuration (systemd/hsad-sim.toml): the axis
// loop on the real sim plugin in lockstep, one driver read, one AxisLoop::cycle, one driver write
// per simulated 100 µs, as tests/daemon/test_axis_loop.cpp runs it, but with the AxisParams hsad
// builds from the example. Every move across the stroke and at 0, 3 and 6 kg must reach its target
// with at most 0.2 mm of overshoot, be within 0.1 mm of it 0.3 s after its profile ends, and never
// hold the valve command saturated for more than a few cycles. The figures are printed, and the
// same runs with parts of the motion control switched off show what each part contributes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <toml++/toml.h>

#include "control/laws/direct_servo/direct_servo_law.hpp"
#include "daemon/axis/axis_loop.hpp"
#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"
#include "drivers/plugin_loader.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t kPeriodNs = 100'000;
constexpr double kMaxOvershootM = 0.2e-3;
constexpr double kSettleBandM = 0.1e-3;
constexpr double kSettleAfterS = 0.3;
constexpr int kMaxSaturatedStreak = 10;  // base cycles: one PI sample (1 ms) held at the limit

std::string example(const std::string& file = "hsad-sim.toml") {
  std::ifstream in(std::string(HSA_SOURCE_DIR) + "/systemd/" + file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The example with `key = value` lines set in [axes.pi] (replacing one that is there).
std::string with_pi_keys(std::string text, const std::string& lines) {
  const std::string table = "[axes.pi]\n";
  const std::size_t at = text.find(table);
  EXPECT_NE(at, std::string::npos);
  std::istringstream in(lines);
  for (std::string line; std::getline(in, line);) {
    const std::string key = line.substr(0, line.find(' '));
    const std::size_t existing = text.find("\n" + key + " ", at);
    if (existing != std::string::npos && existing < text.find("\n[", at + 1)) {
      text.erase(existing + 1, text.find('\n', existing + 1) - existing);
    }
  }
  text.insert(at + table.size(), lines);
  return text;
}

// What a variant changes against the example configuration.
struct Variant {
  const char* name;
  std::string pi_keys;                     // [axes.pi] lines
  std::optional<double> jerk_m_s3;         // the move's jerk (1e12: a trapezoid)
  double speed_m_s = 0.0;                  // the move's speed (0: the axis's)
  double accel_m_s2 = 0.0;                 // the move's acceleration (0: the axis's)
  bool hold_integral = true;               // PiParams::hold_integral_while_planned
  std::string config = "";                 // a whole configuration instead of the example's
};

struct Figures {
  double overshoot_m = 0.0;        // past the target, in the move's direction
  double error_after_m = 0.0;      // |error| 0.3 s after the profile's end
  double settle_s = 0.0;           // after the profile's end, until |error| stays within 0.1 mm
  int saturated_streak = 0;        // longest run of base cycles with the command saturated
  double peak_opening = 0.0;
  bool faulted = false;
};

Figures run_move(double start, double target, double load_kg, const Variant& v = {"", "", {}, 0.0, 0.0, true}) {
  const std::string text = with_pi_keys(v.config.empty() ? example() : v.config, v.pi_keys);
  const DaemonConfig config = parse_config(text, "hsad.toml");
  AxisParams params = axis_params(config.axes.at(0), config.realtime);
  if (v.jerk_m_s3) params.safety.max_jerk_m_s3 = *v.jerk_m_s3;
  if (v.accel_m_s2 > 0.0) params.safety.max_accel_m_s2 = v.accel_m_s2;
  if (v.speed_m_s > 0.0) {
    // A faster axis than the example's: its setpoint rate limit too.
    control::PiParams pi = dynamic_cast<const control::PiCascadeLaw&>(*params.law).cascade().params().cylinder;
    pi.max_setpoint_rate_m_s = params.safety.max_speed_m_s = v.speed_m_s;
    pi.hold_integral_while_planned = v.hold_integral;
    params.law = std::make_shared<control::DirectServoLaw>(pi, 10, params.law->gain_bounds());
  } else if (!v.hold_integral) {
    control::PiParams pi = dynamic_cast<const control::PiCascadeLaw&>(*params.law).cascade().params().cylinder;
    pi.hold_integral_while_planned = false;
    params.law = std::make_shared<control::DirectServoLaw>(pi, 10, params.law->gain_bounds());
  }
  // The configuration's own rig (its sim driver's settings), in lockstep, loaded and placed.
  toml::table settings = *toml::parse(text)["drivers"][0]["settings"].as_table();
  settings.insert_or_assign("valve", "servo");
  settings.insert_or_assign("timing", "lockstep");
  settings.insert_or_assign("seed", 1);
  settings.insert_or_assign("load_kg", load_kg);
  settings.insert_or_assign("initial_position_m", start);
  std::unique_ptr<io::DriverHandle> driver = io::PluginLoader({HSA_PLUGIN_DIR}).load_driver("rig", "sim", settings);
  io::DriverHandle* drivers[] = {driver.get()};
  AxisLoop loop(params, bind_axis_signals("lift", params.bindings, drivers));
  EXPECT_TRUE(driver->activate().ok());

  std::int64_t t = 0;
  AxisInputsFromOperator op;
  Figures f;
  int streak = 0;
  auto cycle = [&] {
    const io::Timestamp now{t};
    EXPECT_EQ(driver->read(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    loop.cycle(t, op);
    EXPECT_EQ(driver->write(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    t += kPeriodNs;
    const bool saturated = loop.law().saturated() && loop.telemetry().state == AxisState::enabled;
    streak = saturated ? streak + 1 : 0;
    f.saturated_streak = std::max(f.saturated_streak, streak);
    f.peak_opening = std::max(f.peak_opening, std::abs(loop.telemetry().opening));
    f.faulted = f.faulted || loop.telemetry().state == AxisState::fault;
  };
  auto command = [&](CommandKind kind, MoveRequest move = {}) {
    op.command = {op.command.seq + 1, kind, ControlMode::position, move, 0};
    cycle();
  };
  for (int i = 0; i < 5; ++i) cycle();
  command(CommandKind::enable);
  // Let the rod settle where it starts (enable holds it there), then start the move from rest.
  for (int i = 0; i < 5'000; ++i) cycle();
  command(CommandKind::move_to, {target, v.speed_m_s, v.accel_m_s2});
  EXPECT_TRUE(loop.supervisor().last_command().accepted);
  const control::JerkLimitedProfile& profile = loop.supervisor().move();
  const std::int64_t end_ns = t + std::llround(profile.duration_s() * 1e9);
  const double direction = target >= start ? 1.0 : -1.0;
  double last_outside_s = 0.0;
  while (t < end_ns + 1'000'000'000) {
    cycle();
    const double error = loop.telemetry().position_m - target;
    const double after_s = static_cast<double>(t - end_ns) * 1e-9;
    f.overshoot_m = std::max(f.overshoot_m, direction * error);
    if (after_s <= kSettleAfterS) f.error_after_m = std::abs(error);
    if (std::abs(error) > kSettleBandM) last_outside_s = after_s;
  }
  f.settle_s = std::max(0.0, last_outside_s);
  return f;
}

struct Case {
  double start, target, load_kg;
};

constexpr Case kCases[] = {
    {0.020, 0.280, 0.0}, {0.020, 0.280, 3.0}, {0.020, 0.280, 6.0}, {0.280, 0.020, 0.0}, {0.280, 0.020, 6.0},
    {0.060, 0.200, 0.0}, {0.060, 0.200, 6.0}, {0.200, 0.060, 0.0}, {0.200, 0.060, 3.0}, {0.200, 0.060, 6.0},
    {0.150, 0.160, 0.0}, {0.150, 0.160, 6.0}, {0.160, 0.150, 0.0}, {0.160, 0.150, 6.0}, {0.030, 0.020, 6.0},
};

void print(const char* variant, const Case& c, const Figures& f) {
  std::printf("%-14s %5.0f -> %5.0f mm %2.0f kg: overshoot %6.3f mm, |error| at +0.3 s %6.3f mm, "
              "settled %5.3f s after the profile, saturated %5d cycles, peak opening %5.3f%s\n",
              variant, c.start * 1e3, c.target * 1e3, c.load_kg, f.overshoot_m * 1e3, f.error_after_m * 1e3,
              f.settle_s, f.saturated_streak, f.peak_opening, f.faulted ? ", FAULT" : "");
}

TEST(Moves, EveryExampleMoveReachesItsTargetWithoutOvershootOrSaturation) {
  for (const Case& c : kCases) {
    const Figures f = run_move(c.start, c.target, c.load_kg);
    print("example", c, f);
    EXPECT_FALSE(f.faulted);
    EXPECT_LE(f.overshoot_m, kMaxOvershootM) << c.start << " -> " << c.target << " at " << c.load_kg << " kg";
    EXPECT_LE(f.error_after_m, kSettleBandM) << c.start << " -> " << c.target << " at " << c.load_kg << " kg";
    EXPECT_LE(f.saturated_streak, kMaxSaturatedStreak) << c.start << " -> " << c.target << " at " << c.load_kg << " kg";
  }
}

// A rig nobody tuned for: the custom 32/16 mm rig of systemd/hsad-sim-custom-rig.toml (its
// feed-forward inverts its 200 mm plant), bounded by the capability of the plant set identified on
// it (tests/daemon/data/custom-rig-plants.toml: retracting 0.0914 m/s, so the speed is 0.09 m/s),
// over its 0.01–0.39 m soft limits, at 0, 3 and 6 kg. Every move arrives (within 0.1 mm 0.3 s after
// its profile), never saturates and never faults. The overshoot is printed, not held to the
// example's 0.2 mm, because it misses it: 0.24 mm extending 20 -> 380 mm with 6 kg, 0.32 mm 60 ->
// 300 mm with 3 kg (0.04–0.08 mm in the other cases). The cause is the feed-forward from one
// plant: the identified k01 rises from 0.151 m/s at 200 mm to 0.167 m/s at 300 mm, so 1/k01 at
// 200 mm pushes the rod ahead of its profile at the stroke's far end (with 1/k01 of 300 mm the
// worst is 0.13 mm). Feed-forward per working point from the identified set is the cure, not done.
constexpr Case kCustomRigCases[] = {
    {0.020, 0.380, 0.0}, {0.020, 0.380, 6.0}, {0.380, 0.020, 0.0}, {0.380, 0.020, 6.0}, {0.060, 0.300, 3.0},
    {0.300, 0.060, 3.0}, {0.200, 0.210, 0.0}, {0.210, 0.200, 6.0}, {0.030, 0.020, 6.0},
};

TEST(Moves, EveryMoveOnARigNobodyTunedForArrivesWithinItsIdentifiedCapability) {
  std::string text = example("hsad-sim-custom-rig.toml");
  const std::string plants = std::string(HSA_SOURCE_DIR) + "/tests/daemon/data/custom-rig-plants.toml";
  const std::size_t speed = text.find("max_speed_m_s = 0.1\n");
  ASSERT_NE(speed, std::string::npos);
  text.replace(speed, std::string("max_speed_m_s = 0.1\n").size(),
               "max_speed_m_s = 0.09\nplants = \"" + plants + "\"\n");
  const Variant custom{"custom rig", "", {}, 0.0, 0.0, true, text};
  for (const Case& c : kCustomRigCases) {
    const Figures f = run_move(c.start, c.target, c.load_kg, custom);
    print("custom rig", c, f);
    EXPECT_FALSE(f.faulted);
    EXPECT_LE(f.error_after_m, kSettleBandM) << c.start << " -> " << c.target << " at " << c.load_kg << " kg";
    EXPECT_LE(f.saturated_streak, kMaxSaturatedStreak) << c.start << " -> " << c.target << " at " << c.load_kg << " kg";
  }
}

// Worst figures of a variant over every case.
Figures worst_of(const Variant& v) {
  Figures w;
  for (const Case& c : kCases) {
    const Figures f = run_move(c.start, c.target, c.load_kg, v);
    if (std::getenv("HSA_MOVES_VERBOSE")) print(v.name, c, f);
    w.overshoot_m = std::max(w.overshoot_m, f.overshoot_m);
    w.error_after_m = std::max(w.error_after_m, f.error_after_m);
    w.settle_s = std::max(w.settle_s, f.settle_s);
    w.saturated_streak = std::max(w.saturated_streak, f.saturated_streak);
    w.peak_opening = std::max(w.peak_opening, f.peak_opening);
    w.faulted = w.faulted || f.faulted;
  }
  std::printf("| %-34s | %6.3f | %6.3f | %5.3f | %5d | %5.3f | %s |\n", v.name, w.overshoot_m * 1e3, w.error_after_m * 1e3,
              w.settle_s, w.saturated_streak, w.peak_opening, w.faulted ? "yes" : "no");
  return w;
}

// Each part of the motion control against the same moves, added one at a time: the worst of each
// figure over every case, as a table (docs/operation.md, Moves, reproduces it).
TEST(Moves, EachPartOfTheMotionControlContributes) {
  const std::string no_ff = "velocity_feedforward = 0\nacceleration_feedforward = 0\njerk_feedforward = 0\n";
  const std::string v_ff = "acceleration_feedforward = 0\njerk_feedforward = 0\n";
  const std::string va_ff = "jerk_feedforward = 0\n";
  constexpr double kTrapezoid = 1e12;  // a jerk no move notices
  std::printf("| %-34s | overshoot mm | error +0.3 s mm | settled s | saturated cycles | peak opening | fault |\n",
              "variant (worst of every case)");
  const Figures old = worst_of({"trapezoid, PI only, 0.2 m/s", no_ff, kTrapezoid, 0.2, 2.0, false});
  const Figures baseline = worst_of({"trapezoid, PI only", no_ff, kTrapezoid, 0.0, 0.0, false});
  const Figures s_curve = worst_of({"+ S-curve", no_ff, {}, 0.0, 0.0, false});
  const Figures velocity = worst_of({"+ velocity FF", v_ff, {}, 0.0, 0.0, false});
  const Figures accel = worst_of({"+ acceleration FF", va_ff, {}, 0.0, 0.0, false});
  const Figures jerk = worst_of({"+ jerk FF", "", {}, 0.0, 0.0, false});
  const Figures held = worst_of({"+ integrator held (the example)", "", {}, 0.0, 0.0, true});
  const Figures no_s = worst_of({"the example with a trapezoid", "", kTrapezoid, 0.0, 0.0, true});
  const Figures held_va = worst_of({"the example without jerk FF", va_ff, {}, 0.0, 0.0, true});
  const Figures held_v = worst_of({"velocity FF + integrator held", v_ff, {}, 0.0, 0.0, true});
  EXPECT_TRUE(old.faulted);  // what the old defaults did with a load
  EXPECT_FALSE(baseline.faulted);  // the slower speed alone no longer saturates
  EXPECT_LT(velocity.overshoot_m, s_curve.overshoot_m);
  EXPECT_LT(accel.overshoot_m, velocity.overshoot_m);
  EXPECT_LT(held.overshoot_m, accel.overshoot_m);
  EXPECT_LT(held.settle_s, baseline.settle_s);
  EXPECT_LT(held.overshoot_m, no_s.overshoot_m);
  EXPECT_LT(held.overshoot_m, held_v.overshoot_m);
  (void)jerk;
  (void)held_va;
}

}  // namespace
}  // namespace hsa::daemon
