// axis_params: the configuration's thresholds, given in seconds, become the base ticks the
// supervisor counts at the configuration's own base period, per axis, and an unconfigured
// supervisor judges as an axis whose configuration leaves them at their defaults.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"

namespace hsa::daemon {
namespace {

std::string example(const std::string& name) {
  std::ifstream in(std::string(HSA_SOURCE_DIR) + "/systemd/" + name);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(AxisSetup, TimesInSecondsBecomeTicksAtTheConfiguredBasePeriod) {
  // The Modbus example runs a 1 ms base tick and allows 0.1 s of following error and staleness.
  const DaemonConfig c = parse_config(example("hsad-modbus-simdev.toml"), "hsad-modbus-simdev.toml");
  ASSERT_EQ(c.realtime.base_period_us, 1000u);
  const AxisParams p = axis_params(c.axes.at(0), c.realtime);
  EXPECT_EQ(p.safety.following_error_cycles, 100u);
  EXPECT_EQ(p.safety.encoder_stale_cycles, 100u);
  EXPECT_EQ(p.safety.saturation_cycles, 500u);
}

TEST(AxisSetup, EachAxisKeepsItsOwnThresholds) {
  std::string text = example("hsad-sim-two-axes.toml");
  // Give the second axis its own following-error time; the first keeps the default.
  const std::size_t second = text.find("[axes.safety]", text.find("[axes.safety]") + 1);
  ASSERT_NE(second, std::string::npos);
  text.insert(second + std::string("[axes.safety]").size(), "\nfollowing_error_s = 0.05");
  const DaemonConfig c = parse_config(text, "two-axes.toml");
  ASSERT_EQ(c.axes.size(), 2u);
  EXPECT_EQ(axis_params(c.axes[0], c.realtime).safety.following_error_cycles, 100u);  // 0.01 s at 100 us
  EXPECT_EQ(axis_params(c.axes[1], c.realtime).safety.following_error_cycles, 500u);  // 0.05 s at 100 us
}

TEST(AxisSetup, AnUnconfiguredSupervisorJudgesAsTheConfigurationsDefaults) {
  const DaemonConfig c = parse_config(
      replaced(example("hsad-sim.toml"), "encoder_stale_s = 0.001", ""), "hsad-sim.toml");
  ASSERT_EQ(c.realtime.base_period_us, 100u);  // the default base period
  const SupervisorParams configured = axis_params(c.axes.at(0), c.realtime).safety;
  const SupervisorParams unconfigured;
  EXPECT_EQ(configured.encoder_stale_cycles, unconfigured.encoder_stale_cycles);
  EXPECT_EQ(configured.following_error_cycles, unconfigured.following_error_cycles);
  EXPECT_EQ(configured.saturation_cycles, unconfigured.saturation_cycles);
  EXPECT_EQ(configured.input_stale_ns, unconfigured.input_stale_ns);
  EXPECT_EQ(configured.setpoint_timeout_ns, unconfigured.setpoint_timeout_ns);
}

// The axis's plant set reaches its supervisor: the capability per direction, and the acceleration
// a move gets when the configuration sets none (the speed reached in 0.1 s, 0.9 m/s², under the
// smaller limit; daemon/config/capability_check.hpp), which a move's direction bounds in turn.
// Without a plant set both stay as they were: no capability, the configured acceleration.
TEST(AxisSetup, ThePlantSetsCapabilityBoundsTheSupervisorsMoves) {
  const std::string set = std::string(HSA_SOURCE_DIR) + "/tests/daemon/data/custom-rig-plants.toml";
  std::string text = replaced(example("hsad-sim.toml"), "# plants = \"plants.toml\"", "plants = \"" + set + "\"");
  text = replaced(replaced(text, "max_speed_m_s = 0.15 ", "max_speed_m_s = 0.09 "), "max_accel_m_s2 = 1.5", "");
  const DaemonConfig c = parse_config(text, "hsad-sim.toml");
  const SupervisorParams p = axis_params(c.axes.at(0), c.realtime).safety;
  EXPECT_DOUBLE_EQ(p.capability.extend.speed_m_s, 0.10492161932166391);
  EXPECT_DOUBLE_EQ(p.capability.extend.accel_m_s2, 8.102860038574239);
  EXPECT_DOUBLE_EQ(p.capability.retract.speed_m_s, 0.0913784275612689);
  EXPECT_DOUBLE_EQ(p.capability.retract.accel_m_s2, 7.056949881835035);
  EXPECT_TRUE(std::isinf(p.max_accel_m_s2));
  EXPECT_DOUBLE_EQ(move_bounds(p).accel_m_s2, 0.09 / 0.1);

  const DaemonConfig none = parse_config(example("hsad-sim.toml"), "hsad-sim.toml");
  const SupervisorParams q = axis_params(none.axes.at(0), none.realtime).safety;
  EXPECT_TRUE(std::isinf(q.capability.extend.speed_m_s));
  EXPECT_TRUE(std::isinf(q.capability.retract.accel_m_s2));
  EXPECT_DOUBLE_EQ(q.max_accel_m_s2, 1.5);
}

}  // namespace
}  // namespace hsa::daemon
