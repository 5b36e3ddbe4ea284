// The proportional valve's time-optimal moves (control/valve_time_optimal.hpp) on top of the
// model-inverse law: the switching curve's prediction on the model, a jump driven at full current,
// braked, driven again until the force current is rebuilt and handed back without passing the
// target, and no move at all on references the
// reference filter follows (the law is then the model-inverse's, sample for sample).
//
// The plant here is the valve the law assumes, written out independently: the current delayed by
// whole samples, the play of width w, the lag τa, the spool mode, integrated at T/20, its state
// measured exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "control/valve_law.hpp"

namespace hsa::control {
namespace {

constexpr double kT = 1e-4;

IdentifiedValve paper_like() {
  IdentifiedValve v;
  v.gain_m_per_a = 18.0 / 9870.0;
  v.rest_position_m = -2.5e-3;
  v.natural_frequency_hz = 50.0;
  v.damping_ratio = 0.3;
  v.magnetic_lag_s = 1.5e-3;
  v.width_a = 0.3;
  v.delay_s = 0.3e-3;
  v.current_max_a = 3.0;
  return v;
}

class ModelValve {
 public:
  ModelValve(const IdentifiedValve& v, double position_m) : v_(v), x_(position_m) {
    const double force = (position_m - v.rest_position_m) / v.gain_m_per_a;
    play_ = force_ = force;
    for (long k = 0; k < std::lround(v.delay_s / kT); ++k) pending_.push_back(force + 0.5 * v.width_a);
  }
  void step(double current_a) {
    pending_.push_back(current_a);
    const double in = pending_.front();
    pending_.pop_front();
    if (in > play_ + v_.width_a) play_ = in - v_.width_a;
    if (in < play_) play_ = in;
    const double w0 = 2.0 * std::numbers::pi * v_.natural_frequency_hz;
    const double h = kT / 20.0;
    for (int k = 0; k < 20; ++k) {
      force_ += h / v_.magnetic_lag_s * (play_ - force_);
      a_ = w0 * w0 * (v_.rest_position_m + v_.gain_m_per_a * force_ - x_) - 2.0 * v_.damping_ratio * w0 * speed_;
      speed_ += h * a_;
      x_ += h * speed_;
    }
  }
  [[nodiscard]] PredictorOutput state() const { return {x_, speed_, a_}; }

 private:
  IdentifiedValve v_;
  std::deque<double> pending_;
  double play_ = 0.0, force_ = 0.0, x_ = 0.0, speed_ = 0.0, a_ = 0.0;
};

// The law on the model valve, from rest at `from`, the reference `r(k)` at sample k.
struct LoopRun {
  std::vector<double> current, position;
  std::uint64_t moves = 0;
};
template <class Reference>
LoopRun run(ValveLawStep step, double from, int samples, Reference r) {
  ModelValve valve(paper_like(), from);
  ValveLaw law(identified_valve_law(paper_like(), step));
  LoopRun out;
  for (int k = 0; k < samples; ++k) {
    out.current.push_back(law.update(r(k), valve.state()));
    valve.step(out.current.back());
    out.position.push_back(valve.state().position_m);
  }
  out.moves = law.time_optimal().moves();
  return out;
}

// 10–90 % time and peak progress of a jump from −a to +a at sample `at`.
struct Jump {
  double rise_s = NAN, peak = -INFINITY;
};
Jump jump_of(const LoopRun& run, double a, int at) {
  double t10 = NAN, t90 = NAN;
  Jump j;
  for (std::size_t k = static_cast<std::size_t>(at); k < run.position.size(); ++k) {
    const double progress = (run.position[k] + a) / (2.0 * a);
    if (std::isnan(t10) && progress >= 0.1) t10 = static_cast<double>(k) * kT;
    if (std::isnan(t90) && progress >= 0.9) t90 = static_cast<double>(k) * kT;
    j.peak = std::max(j.peak, progress);
  }
  j.rise_s = t90 - t10;
  return j;
}

TEST(ValveTimeOptimal, TheSwitchingCurvesStopIsTheModelsFirstPeak) {
  const IdentifiedValve v = paper_like();
  const double a = 0.625e-3;
  // The current that holds the spool at −a without dither: the play at rest sits at it − w/2.
  const double hold = (-a - v.rest_position_m) / v.gain_m_per_a + 0.5 * v.width_a;
  ValveTimeOptimal to(identified_time_optimal(v, kT), kT, v.current_max_a);
  for (int k = 0; k < 1000; ++k) to.commanded(hold);
  const PredictorOutput rest{.position_m = -a};
  // Holding, it stays.
  EXPECT_NEAR(to.stop_under(hold, 1.0, rest), -a, 1e-7);
  for (const double direction : {1.0, -1.0}) {
    // The model valve, from the same rest, under the constant current: its first turn.
    const double current = direction > 0.0 ? v.current_max_a : 0.0;
    ModelValve valve(v, -a);
    double peak = -INFINITY;
    for (int k = 0; k < 400; ++k) {
      valve.step(current);
      peak = std::max(peak, direction * valve.state().position_m);
      if (k > 5 && direction * valve.state().velocity_m_s <= 0.0) break;
    }
    const double predicted = to.stop_under(current, direction, rest);
    std::printf("  direction %+.0f: stop %.1f um, the model valve's %.1f um\n", direction, predicted * 1e6, peak * 1e6);
    EXPECT_NEAR(predicted, peak, 0.01 * std::abs(peak + direction * a));
    EXPECT_GT(predicted, direction * -a + 1e-3);  // a real move: over a millimetre
  }
}

TEST(ValveTimeOptimal, AJumpIsDrivenAtFullCurrentBrakedAndHandedBackShortOfTheTarget) {
  const double a = 0.625e-3;
  const int at = 500;  // 50 ms at rest on −a first
  const auto square = [&](int k) { return k < at ? -a : a; };
  const LoopRun to = run(ValveLawStep::time_optimal, -a, 900, square);
  const LoopRun mi = run(ValveLawStep::damped, -a, 900, square);  // the linear law under the moves
  EXPECT_EQ(to.moves, 1u);
  // Before the jump the two laws are one.
  for (int k = 0; k < at; ++k) ASSERT_EQ(to.current[k], mi.current[k]) << k;
  // Full current from the jump on, then zero, then the linear law.
  const double i_max = paper_like().current_max_a;
  EXPECT_EQ(to.current[at], i_max);
  int k = at;
  while (to.current[k] == i_max) ++k;
  const int drive_end = k;
  while (to.current[k] == 0.0) ++k;
  const int brake_end = k;
  std::printf("  drive %.1f ms, brake %.1f ms\n", (drive_end - at) * kT * 1e3, (brake_end - drive_end) * kT * 1e3);
  EXPECT_GT(drive_end - at, 10);  // over 1 ms of full effort
  EXPECT_GT(brake_end - drive_end, 2);
  EXPECT_EQ(to.moves, 1u);  // the linear law finishes the move (it may clip at I_max on the last stretch)
  const Jump fast = jump_of(to, a, at);
  const Jump slow = jump_of(mi, a, at);
  std::printf("  10-90 %% %.2f ms (model-inverse %.2f ms), peak %.3f (%.3f)\n", fast.rise_s * 1e3, slow.rise_s * 1e3,
              fast.peak, slow.peak);
  EXPECT_LT(fast.rise_s, 0.8 * slow.rise_s);
  EXPECT_LE(fast.rise_s, 0.8 * 2.0 * a / 0.25);  // 0.25 m/s on the model itself
  // Braked onto the target: less overshoot than the model-inverse law's own, and on the target
  // 35 ms later.
  EXPECT_LT(fast.peak, slow.peak);
  EXPECT_NEAR(to.position.back(), a, 10e-6);
}

// Braking drains the lagged force current far below the target's: a spool that stopped there
// would be thrown back by its spring. The move therefore drives again (the rebuild) before it
// settles, and the spool, once it first turns past 90 % of the jump, stays near the target.
TEST(ValveTimeOptimal, TheForceCurrentIsRebuiltBeforeTheMoveSettles) {
  const double a = 0.625e-3;
  const int at = 500;
  for (const double direction : {1.0, -1.0}) {
    const auto square = [&](int k) { return direction * (k < at ? -a : a); };
    const LoopRun to = run(ValveLawStep::time_optimal, -direction * a, 900, square);
    const double drive = direction > 0.0 ? paper_like().current_max_a : 0.0;
    const double brake = direction > 0.0 ? 0.0 : paper_like().current_max_a;
    int k = at;
    while (to.current[k] == drive) ++k;
    const int drive_end = k;
    while (to.current[k] == brake) ++k;
    const int brake_end = k;
    while (to.current[k] == drive) ++k;
    const int rebuild_end = k;
    // The largest |x − target| from the spool's first turn after its 90 % crossing.
    double arrival = 0.0, last = -INFINITY;
    bool crossed = false, turned = false;
    for (std::size_t j = static_cast<std::size_t>(at); j < to.position.size(); ++j) {
      const double progress = (direction * to.position[j] + a) / (2.0 * a);
      crossed = crossed || progress >= 0.9;
      turned = turned || (crossed && progress < last);
      if (turned) arrival = std::max(arrival, std::abs(direction * a - to.position[j]));
      last = progress;
    }
    std::printf("  direction %+.0f: drive %.1f ms, brake %.1f ms, rebuild %.1f ms; after arrival |error| up to %.1f um\n",
                direction, (drive_end - at) * kT * 1e3, (brake_end - drive_end) * kT * 1e3,
                (rebuild_end - brake_end) * kT * 1e3, arrival * 1e6);
    EXPECT_GT(brake_end - drive_end, 2);
    EXPECT_GT(rebuild_end - brake_end, 2);  // over 0.2 ms of full effort after the braking
    EXPECT_LT(arrival, 0.05 * 2.0 * a);
  }
}

// A reference the filter follows never triggers: the law is the damped step's, sample for sample.
TEST(ValveTimeOptimal, NoMoveOnAReferenceTheFilterFollows) {
  const double a = 0.875e-3;
  const auto triangle = [&](int k) {
    const double p = std::fmod(k * kT * 10.0, 1.0);
    return a * (p < 0.25 ? 4.0 * p : p < 0.75 ? 2.0 - 4.0 * p : 4.0 * p - 4.0);
  };
  const auto steep = [&](int k) { return std::min(0.1 * k * kT, a); };  // 0.1 m/s: three times the triangle's
  const auto sine100 = [&](int k) { return 0.05 * 1.25e-3 * std::sin(2.0 * std::numbers::pi * 100.0 * k * kT); };
  const auto sine300 = [&](int k) { return 0.05 * 1.25e-3 * std::sin(2.0 * std::numbers::pi * 300.0 * k * kT); };
  const auto check = [](const LoopRun& to, const LoopRun& mi) {
    EXPECT_EQ(to.moves, 0u);
    EXPECT_EQ(to.current, mi.current);
  };
  check(run(ValveLawStep::time_optimal, 0.0, 2000, triangle), run(ValveLawStep::damped, 0.0, 2000, triangle));
  check(run(ValveLawStep::time_optimal, 0.0, 2000, steep), run(ValveLawStep::damped, 0.0, 2000, steep));
  check(run(ValveLawStep::time_optimal, 0.0, 2000, sine100), run(ValveLawStep::damped, 0.0, 2000, sine100));
  check(run(ValveLawStep::time_optimal, 0.0, 2000, sine300), run(ValveLawStep::damped, 0.0, 2000, sine300));
}

// A target the valve cannot hold (its force current beyond what I_max reaches through the play,
// or below 0): the rebuild ends short of the unreachable force current and the move hands back;
// it never keeps the current at a limit.
TEST(ValveTimeOptimal, AMoveToATargetBeyondTheValvesReachStillHandsBack) {
  const double a = 0.625e-3;
  const IdentifiedValve v = paper_like();
  for (const double target : {3.5e-3, -3.5e-3}) {  // force currents 3.3 A and -0.55 A: out of [0, I_max - w]
    ValveLaw law(identified_valve_law(v, ValveLawStep::time_optimal));
    ModelValve valve(v, -a);
    int last_move_sample = -1;
    for (int k = 0; k < 1500; ++k) {
      valve.step(law.update(k < 500 ? -a : target, valve.state()));
      if (law.time_optimal().mode() != ValveTimeOptimal::Mode::track) last_move_sample = k;
    }
    std::printf("  target %+.1f mm: the move ran until %.1f ms after the jump\n", target * 1e3,
                (last_move_sample - 500) * kT * 1e3);
    EXPECT_EQ(law.time_optimal().moves(), 1u);
    EXPECT_GT(last_move_sample, 500);
    EXPECT_LT(last_move_sample, 500 + 300);  // handed back within 30 ms
  }
}

// Skipped periods inside a move: the drive held the last current, and the moves' model, which
// runs open loop through the move, steps once per missed period with it (as a ValveTimeOptimal
// told each of those currents does), so that it is not left behind the spool.
TEST(ValveTimeOptimal, AGapInAMoveStepsTheModelWithTheHeldCurrent) {
  const double a = 0.625e-3;
  const ValveLawParams p = identified_valve_law(paper_like(), ValveLawStep::time_optimal);
  ValveLaw law(p);
  ModelValve valve(paper_like(), -a);
  for (int k = 0; k < 520; ++k) {
    const double current = law.update(k < 500 ? -a : a, valve.state());
    valve.step(current);
  }
  ASSERT_NE(law.time_optimal().mode(), ValveTimeOptimal::Mode::track);  // inside the move
  ValveTimeOptimal told = law.time_optimal();  // from here on told each current the drive applied
  const double held = law.current();
  for (int k = 0; k < 4; ++k) {
    told.commanded(held);
    valve.step(held);
  }
  const double before = told.model_state().position_m;
  told.commanded(law.update(a, valve.state(), 5));
  EXPECT_GT(std::abs(told.model_state().position_m - before), 1e-6);  // the model moves in the gap's time
  EXPECT_EQ(law.time_optimal().model_state().position_m, told.model_state().position_m);
  EXPECT_EQ(law.time_optimal().model_force_a(), told.model_force_a());
}

TEST(ValveTimeOptimal, SettingsComeFromTheIdentifiedValve) {
  const IdentifiedValve v = paper_like();
  const ValveLawParams p = identified_valve_law(v, ValveLawStep::time_optimal);
  const ValveLawParams damped = identified_valve_law(v, ValveLawStep::damped);
  EXPECT_TRUE(p.time_optimal.enabled);
  EXPECT_FALSE(damped.time_optimal.enabled);
  ValveLawParams without = p;
  without.time_optimal = {};
  EXPECT_EQ(without, damped);  // the linear law and its predictor are the damped step's
  EXPECT_TRUE(p.model_predictor.enabled);
  EXPECT_EQ(p.model_predictor.valve, v);
  EXPECT_EQ(p.time_optimal.gain_m_per_a, v.gain_m_per_a);
  EXPECT_EQ(p.time_optimal.natural_frequency_hz, v.natural_frequency_hz);
  EXPECT_EQ(p.time_optimal.magnetic_lag_s, v.magnetic_lag_s);
  // d_on = g·I_max·ω0·T: 172 µm for the paper's valve.
  EXPECT_NEAR(p.time_optimal.trigger_m, v.gain_m_per_a * 3.0 * 2.0 * std::numbers::pi * 50.0 * kT, 1e-12);
}

TEST(ValveTimeOptimal, RefusesANonPhysicalModel) {
  const ValveTimeOptimalParams good = identified_time_optimal(paper_like(), kT);
  EXPECT_NO_THROW(ValveTimeOptimal(good, kT, 3.0));
  ValveTimeOptimalParams p = good;
  p.gain_m_per_a = 0.0;
  EXPECT_THROW(ValveTimeOptimal(p, kT, 3.0), std::invalid_argument);
  p = good;
  p.damping_ratio = NAN;
  EXPECT_THROW(ValveTimeOptimal(p, kT, 3.0), std::invalid_argument);
  p = good;
  p.trigger_m = 0.0;
  EXPECT_THROW(ValveTimeOptimal(p, kT, 3.0), std::invalid_argument);
  p = good;
  p.delay_s = 2e-3;  // 20 samples: beyond the fixed delay line
  EXPECT_THROW(ValveTimeOptimal(p, kT, 3.0), std::invalid_argument);
  p = good;
  p.horizon_samples = 0;
  EXPECT_THROW(ValveTimeOptimal(p, kT, 3.0), std::invalid_argument);
  // Off, nothing is checked and nothing happens.
  p.enabled = false;
  ValveTimeOptimal off(p, kT, 3.0);
  off.commanded(1.0);
  EXPECT_TRUE(std::isnan(off.update(1e-3, 0.0, {})));
  EXPECT_EQ(off.moves(), 0u);
}

}  // namespace
}  // namespace hsa::control
