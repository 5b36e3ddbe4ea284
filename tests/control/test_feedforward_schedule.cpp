// The feed-forward schedule (control/feedforward_schedule.hpp): one inverted plant per identified
// rod position, interpolated over the stroke, and the PI controller taking its gains at the
// setpoint's position.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "control/feedforward_schedule.hpp"
#include "control/pi_controller.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {
namespace {

void expect_gains(const FeedforwardGains& actual, const FeedforwardGains& expected) {
  EXPECT_DOUBLE_EQ(actual.velocity, expected.velocity);
  EXPECT_DOUBLE_EQ(actual.accel, expected.accel);
  EXPECT_DOUBLE_EQ(actual.jerk, expected.jerk);
}

constexpr IdentifiedPlant kAt100{100, 0, 8000.0, 90.0, 250.0};
constexpr IdentifiedPlant kAt200{200, 0, 12000.0, 110.0, 200.0};

TEST(FeedforwardSchedule, AtAnIdentifiedPositionItInvertsThatPlant) {
  const std::vector<IdentifiedPlant> plants{kAt200, kAt100};  // any order
  const FeedforwardSchedule s = make_feedforward_schedule(plants);
  ASSERT_EQ(s.count, 2u);
  expect_gains(s.at(0.1), plant_inverse_gains(kAt100.plant()));
  expect_gains(s.at(0.2), plant_inverse_gains(kAt200.plant()));
  EXPECT_DOUBLE_EQ(s.at(0.1).velocity, 1e3 / 250.0);  // 1/k01 in s/m
}

TEST(FeedforwardSchedule, BetweenPositionsItInterpolatesAndBeyondTheEndsItHolds) {
  const std::vector<IdentifiedPlant> plants{kAt100, kAt200};
  const FeedforwardSchedule s = make_feedforward_schedule(plants);
  const FeedforwardGains a = plant_inverse_gains(kAt100.plant());
  const FeedforwardGains b = plant_inverse_gains(kAt200.plant());
  const FeedforwardGains quarter = s.at(0.125);
  EXPECT_NEAR(quarter.velocity, a.velocity + 0.25 * (b.velocity - a.velocity), 1e-12);
  EXPECT_NEAR(quarter.accel, a.accel + 0.25 * (b.accel - a.accel), 1e-15);
  EXPECT_NEAR(quarter.jerk, a.jerk + 0.25 * (b.jerk - a.jerk), 1e-18);
  expect_gains(s.at(0.0), a);
  expect_gains(s.at(-1.0), a);
  expect_gains(s.at(0.4), b);
}

TEST(FeedforwardSchedule, PlantsAtOnePositionAreAveraged) {
  const IdentifiedPlant loaded{100, 6, 6000.0, 80.0, 230.0};
  const std::vector<IdentifiedPlant> plants{kAt100, loaded, kAt200};
  const FeedforwardSchedule s = make_feedforward_schedule(plants);
  ASSERT_EQ(s.count, 2u);
  const FeedforwardGains a = plant_inverse_gains(kAt100.plant());
  const FeedforwardGains b = plant_inverse_gains(loaded.plant());
  EXPECT_DOUBLE_EQ(s.at(0.1).velocity, 0.5 * (a.velocity + b.velocity));
  EXPECT_DOUBLE_EQ(s.at(0.1).accel, 0.5 * (a.accel + b.accel));
}

TEST(FeedforwardSchedule, TableA3GivesElevenPositionsEachTheMeanOfItsThreeLoads) {
  const FeedforwardSchedule s = make_feedforward_schedule(kTableA3);
  ASSERT_EQ(s.count, 11u);
  for (std::size_t i = 1; i < s.count; ++i) EXPECT_GT(s.points[i].position_m, s.points[i - 1].position_m);
  // Kv = 1/k01 averaged: between the slowest and the fastest k01 of the table (224-294 mm/s).
  for (std::size_t i = 0; i < s.count; ++i) {
    EXPECT_GT(s.points[i].gains.velocity, 1e3 / 295.0);
    EXPECT_LT(s.points[i].gains.velocity, 1e3 / 223.0);
  }
}

TEST(FeedforwardSchedule, RefusesWhatCannotBeInvertedOrDoesNotFit) {
  EXPECT_THROW((void)make_feedforward_schedule(std::vector<IdentifiedPlant>{}), std::invalid_argument);
  EXPECT_THROW((void)make_feedforward_schedule(std::vector<IdentifiedPlant>{{100, 0, 8000.0, 90.0, 0.0}}),
               std::invalid_argument);
  EXPECT_THROW((void)make_feedforward_schedule(std::vector<IdentifiedPlant>{{100, 0, -1.0, 90.0, 250.0}}),
               std::invalid_argument);
  std::vector<IdentifiedPlant> many;
  for (int mm = 0; mm <= static_cast<int>(FeedforwardSchedule::kMaxPoints); ++mm) many.push_back({mm, 0, 8000.0, 90.0, 250.0});
  EXPECT_THROW((void)make_feedforward_schedule(many), std::invalid_argument);
  many.pop_back();
  EXPECT_EQ(make_feedforward_schedule(many).count, FeedforwardSchedule::kMaxPoints);
}

// The PI's feed-forward is the schedule's at its (rate-limited) setpoint: with Kp = Ki = 0 the
// output is exactly Kv(r)·v + Ka(r)·a.
TEST(FeedforwardSchedule, ThePiTakesTheGainsAtItsSetpoint) {
  PiParams p;
  p.kp = 0.0;
  p.ki = 0.0;
  p.feedforward_schedule = make_feedforward_schedule(std::vector<IdentifiedPlant>{kAt100, kAt200});
  p.velocity_feedforward = 100.0;  // ignored: the schedule replaces the fixed gains
  PiController pi(p);
  for (const double r : {0.1, 0.15, 0.2}) {
    pi.activate(r, 0.0);
    const SetpointMotion motion{0.05, 0.5, 0.0, true};
    const FeedforwardGains g = p.feedforward_schedule.at(r);
    EXPECT_DOUBLE_EQ(pi.update(r, r, motion), g.velocity * 0.05 + g.accel * 0.5) << r;
  }
}

// The PI keeps the gains of its last setpoint and interpolates again only when the setpoint moved:
// a setpoint that moves away, holds and comes back gets the gains of where it is on every sample.
TEST(FeedforwardSchedule, ThePiTakesTheGainsWhereverTheSetpointMovesAndReturns) {
  PiParams p;
  p.kp = 0.0;
  p.ki = 0.0;
  p.feedforward_schedule = make_feedforward_schedule(std::vector<IdentifiedPlant>{kAt100, kAt200});
  PiController pi(p);
  pi.activate(0.1, 0.0);
  const SetpointMotion motion{0.05, 0.5, 2.0, true};
  for (const double r : {0.1, 0.1, 0.15, 0.15, 0.1, 0.2, 0.2, 0.13, 0.15, 0.25, 0.1}) {
    const FeedforwardGains g = p.feedforward_schedule.at(r);
    EXPECT_DOUBLE_EQ(pi.update(r, r, motion), g.velocity * 0.05 + g.accel * 0.5 + g.jerk * 2.0) << r;
  }
}

TEST(FeedforwardSchedule, ThePiRefusesAScheduleWhosePositionsDoNotIncrease) {
  PiParams p;
  p.feedforward_schedule.count = 2;
  p.feedforward_schedule.points[0] = {0.2, {1.0, 0.0, 0.0}};
  p.feedforward_schedule.points[1] = {0.1, {1.0, 0.0, 0.0}};
  EXPECT_THROW(PiController{p}, std::invalid_argument);
  p.feedforward_schedule.points[1] = {0.3, {-1.0, 0.0, 0.0}};
  EXPECT_THROW(PiController{p}, std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
