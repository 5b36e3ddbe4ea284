// A healthy axis never faults from its own operator's command: the real axis loop and supervisor
// on the simulated rig (the sim plugin in lockstep, as tests/daemon/test_moves.cpp runs it, with
// the AxisParams hsad builds from systemd/hsad-sim.toml), at 0 and 6 kg, driven by the worst an
// operator can command within the axis's limits: MOVE_TO across the whole stroke at the largest
// speed and acceleration, short moves, a move reversed half-way, and streamed setpoints (steps,
// sines at and far beyond the speed and acceleration bounds, a square wave) at 1 kHz, as a
// program or `hsactl sine` streams them. No case may raise a fault. Each case's largest
// |following error|, saturated cycles (total and longest run) and the cycles the supervisor
// counted as a slowed stream are printed; they are figures, not asserted, apart from the fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "daemon/axis/axis_loop.hpp"
#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"
#include "drivers/plugin_loader.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t kPeriodNs = 100'000;  // the example's base period
constexpr std::int64_t kStreamEvery = 10;    // a setpoint every 1 ms: 1 kHz, as hsactl sine sends

std::string example() {
  std::ifstream in(std::string(HSA_SOURCE_DIR) + "/systemd/hsad-sim.toml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Figures {
  double max_following_error_m = 0.0;
  long saturated_cycles = 0;
  long longest_saturated_run = 0;
  std::uint64_t limited_cycles = 0;
  double closest_to_soft_limit_m = 1.0;  // the rod's least distance inside them (< 0: past one)
  bool faulted = false;
  std::string fault;
};

// One rig, one axis, enabled and settled at `start_m`; the scenario then drives it.
class Rig {
 public:
  Rig(double load_kg, double start_m) {
    const DaemonConfig config = parse_config(example(), "hsad-sim.toml");
    params_ = axis_params(config.axes.at(0), config.realtime);
    char settings[256];
    std::snprintf(settings, sizeof settings,
                  "valve = \"servo\"\ntiming = \"lockstep\"\nseed = 1\nload_kg = %.17g\ninitial_position_m = %.17g\n",
                  load_kg, start_m);
    driver_ = io::PluginLoader({HSA_PLUGIN_DIR}).load_driver("rig", "sim", toml::parse(settings));
    io::DriverHandle* drivers[] = {driver_.get()};
    loop_ = std::make_unique<AxisLoop>(params_, bind_axis_signals("lift", params_.bindings, drivers));
    EXPECT_TRUE(driver_->activate().ok());
    for (int i = 0; i < 5; ++i) cycle();
    command(CommandKind::enable);
    run_for(0.5);  // the rod settles where enable holds it
  }

  const SupervisorParams& safety() const { return params_.safety; }
  double position() const { return loop_->telemetry().position_m; }
  double time_s() const { return static_cast<double>(t_) * 1e-9; }

  void cycle() {
    const io::Timestamp now{t_};
    EXPECT_EQ(driver_->read(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    loop_->cycle(t_, op_);
    EXPECT_EQ(driver_->write(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    t_ += kPeriodNs;
    const AxisTelemetry& tm = loop_->telemetry();
    const bool enabled = tm.state == AxisState::enabled;
    const bool saturated = enabled && loop_->law().saturated();
    run_ = saturated ? run_ + 1 : 0;
    f_.saturated_cycles += saturated ? 1 : 0;
    f_.longest_saturated_run = std::max(f_.longest_saturated_run, run_);
    if (enabled) f_.max_following_error_m = std::max(f_.max_following_error_m, std::abs(tm.following_error_m));
    const SupervisorParams& p = params_.safety;
    if (enabled) {
      f_.closest_to_soft_limit_m = std::min(
          {f_.closest_to_soft_limit_m, tm.position_m - p.soft_limit_low_m, p.soft_limit_high_m - tm.position_m});
    }
    if (!enabled && !f_.faulted && (tm.state == AxisState::fault || tm.state == AxisState::estop)) {
      f_.faulted = true;
      f_.fault = std::string(to_string(loop_->supervisor().fault().reason));
    }
  }
  void command(CommandKind kind, MoveRequest move = {}) {
    op_.command = {op_.command.seq + 1, kind, ControlMode::position, move, 0};
    cycle();
  }
  bool move_to(double target_m, double speed_m_s, double accel_m_s2) {
    command(CommandKind::move_to, {target_m, speed_m_s, accel_m_s2});
    return loop_->supervisor().last_command().accepted;
  }
  double move_duration_s() const { return loop_->supervisor().move().duration_s(); }
  void run_for(double seconds) {
    const std::int64_t end = t_ + std::llround(seconds * 1e9);
    while (t_ < end) cycle();
  }
  // Streams target(t) (t from the stream's start) at 1 kHz for `seconds`, positions only, as
  // hsactl sine sends them; then lets the rod settle.
  void stream(const std::function<double(double)>& target, double seconds) {
    const std::int64_t start = t_;
    const std::int64_t end = t_ + std::llround(seconds * 1e9);
    for (std::int64_t k = 0; t_ < end; ++k) {
      if (k % kStreamEvery == 0) {
        op_.setpoint.seq += 1;
        op_.setpoint.target = target(static_cast<double>(t_ - start) * 1e-9);
        op_.setpoint.velocity_m_s = 0.0;
      }
      cycle();
    }
  }
  Figures figures() {
    f_.limited_cycles = loop_->supervisor().setpoint_cycles_limited();
    return f_;
  }

 private:
  AxisParams params_;
  std::unique_ptr<io::DriverHandle> driver_;
  std::unique_ptr<AxisLoop> loop_;
  AxisInputsFromOperator op_;
  std::int64_t t_ = 0;
  long run_ = 0;
  Figures f_;
};

struct Scenario {
  const char* name;
  double start_m;
  std::function<void(Rig&)> drive;
};

double sine(double centre, double ampl, double hz, double t) {
  return centre + ampl * std::sin(2.0 * std::numbers::pi * hz * t);
}

std::vector<Scenario> scenarios() {
  // The example's bounds (systemd/hsad-sim.toml): soft limits 10-290 mm, 0.15 m/s, 1.5 m/s².
  constexpr double lo = 0.010, hi = 0.290, v = 0.15, a = 1.5;
  return {
      {"move full stroke, max speed and accel", 0.150,
       [](Rig& r) {
         EXPECT_TRUE(r.move_to(lo, v, a));
         r.run_for(r.move_duration_s() + 0.5);
         EXPECT_TRUE(r.move_to(hi, v, a));
         r.run_for(r.move_duration_s() + 0.5);
         EXPECT_TRUE(r.move_to(lo, v, a));
         r.run_for(r.move_duration_s() + 0.5);
       }},
      {"short moves 1 mm and 5 mm", 0.150,
       [](Rig& r) {
         for (const double to : {0.151, 0.150, 0.155, 0.150, 0.145}) {
           EXPECT_TRUE(r.move_to(to, v, a));
           r.run_for(r.move_duration_s() + 0.3);
         }
       }},
      {"move reversed half-way", 0.050,
       [](Rig& r) {
         EXPECT_TRUE(r.move_to(0.250, v, a));
         r.run_for(r.move_duration_s() / 2);
         EXPECT_TRUE(r.move_to(0.050, v, a));
         r.run_for(r.move_duration_s() + 0.5);
       }},
      {"streamed step full stroke", lo + 0.002,
       [](Rig& r) {
         r.stream([](double) { return hi; }, 3.0);
         r.stream([](double) { return lo; }, 3.0);
       }},
      {"streamed steps 100 mm and 2 mm", 0.100,
       [](Rig& r) {
         r.stream([](double) { return 0.200; }, 1.5);
         r.stream([](double) { return 0.100; }, 1.5);
         r.stream([](double) { return 0.102; }, 0.5);
         r.stream([](double) { return 0.100; }, 0.5);
       }},
      {"streamed sine 20 mm 1 Hz (within)", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.02, 1.0, t); }, 3.0); }},
      {"streamed sine 50 mm 0.5 Hz (speed)", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.05, 0.5, t); }, 4.0); }},
      {"streamed sine 10 mm 2 Hz (accel)", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.01, 2.0, t); }, 3.0); }},
      {"streamed sine 50 mm 3 Hz", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.05, 3.0, t); }, 3.0); }},
      {"streamed sine 100 mm 2 Hz", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.10, 2.0, t); }, 3.0); }},
      {"streamed sine 130 mm 5 Hz", 0.150, [](Rig& r) { r.stream([](double t) { return sine(0.15, 0.13, 5.0, t); }, 3.0); }},
      {"streamed square 20-280 mm 1 Hz", 0.150,
       [](Rig& r) { r.stream([](double t) { return std::fmod(t, 1.0) < 0.5 ? 0.280 : 0.020; }, 4.0); }},
      {"streamed square 140-160 mm 10 Hz", 0.150,
       [](Rig& r) { r.stream([](double t) { return std::fmod(t, 0.1) < 0.05 ? 0.160 : 0.140; }, 2.0); }},
      {"stream takes over a move", 0.050,
       [](Rig& r) {
         EXPECT_TRUE(r.move_to(0.250, v, a));
         r.run_for(r.move_duration_s() / 2);
         r.stream([](double) { return 0.050; }, 2.0);
       }},
  };
}

TEST(NeverFaults, NoOperatorCommandWithinTheLimitsFaultsAHealthyAxis) {
  std::printf("| %-38s | load | max \\|following error\\| mm | saturated cycles (longest run) | limited cycles | "
              "closest to a soft limit mm | fault |\n",
              "case");
  for (const Scenario& s : scenarios()) {
    for (const double load_kg : {0.0, 6.0}) {
      Rig rig(load_kg, s.start_m);
      s.drive(rig);
      const Figures f = rig.figures();
      std::printf("| %-38s | %2.0f kg | %8.3f | %6ld (%5ld) | %7llu | %7.3f | %s |\n", s.name, load_kg,
                  f.max_following_error_m * 1e3, f.saturated_cycles, f.longest_saturated_run,
                  static_cast<unsigned long long>(f.limited_cycles), f.closest_to_soft_limit_m * 1e3,
                  f.faulted ? f.fault.c_str() : "none");
      EXPECT_FALSE(f.faulted) << s.name << " at " << load_kg << " kg: " << f.fault;
    }
  }
}

}  // namespace
}  // namespace hsa::daemon
