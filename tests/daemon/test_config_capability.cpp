// An axis's configured motion bounds against the capability of the plant-set file it names
// (daemon/config/capability_check.hpp): a max_speed_m_s or max_accel_m_s2 the plant cannot follow
// in one of its directions is refused naming the file, line, key, value, direction, figure and the
// plant set; an unset max_accel_m_s2 stays derived from the speed unless that is over the smaller
// direction's limit, which then bounds it; without a plant set nothing changes.
//
// The plant sets: the simulated rig at 0 kg (docs/plant-set.md's capability table: extending
// 0.170 m/s and 11.8 m/s², retracting 0.206 m/s and 12.1 m/s², margin 0.7), written by the
// plant-set writer with Table A3's 0 kg plants (which the paper's gains pass), so extending is the
// slower and the weaker direction; and the custom rig's identified set (tests/daemon/data), where
// retracting is both.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/plant_table.hpp"
#include "daemon/config/describe.hpp"
#include "daemon/config/load_config.hpp"
#include "plant_set/plant_set_file.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

// A valid configuration with a plant set, every required key and nothing else (test_config.cpp's
// minimal one, with `plants`); PLANTS, SPEED and LIMITS are filled in by config().
constexpr std::string_view kAxis = R"([[drivers]]
name = "rig"
plugin = "sim"

[[axes]]
name = "x"
drive = "direct"
[axes.signals.position]
driver = "rig"
channel = "encoder"
[axes.signals.pressure_a]
driver = "rig"
channel = "pressure_a"
[axes.signals.pressure_b]
driver = "rig"
channel = "pressure_b"
[axes.signals.valve_command]
driver = "rig"
channel = "opening_cmd"
[axes.signals.valve_enable]
driver = "rig"
channel = "valve_enable"
[axes.pi]
kp = KP
ki = 460.0
PLANTS
max_speed_m_s = SPEED
[axes.limits]
soft_min_m = 0.01
soft_max_m = 0.29
LIMITS
[axes.safety]
max_pressure_pa = 30e5
max_following_error_m = 0.02
encoder_jump_m = 0.005
)";

std::string replaced(std::string text, std::string_view from, std::string_view to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string config(std::string_view plants, std::string_view speed, std::string_view limits = "",
                   std::string_view kp = "85.0") {
  std::string text = replaced(std::string(kAxis), "KP", kp);
  text = replaced(text, "PLANTS", plants.empty() ? "" : "plants = \"" + std::string(plants) + "\"");
  text = replaced(text, "SPEED", speed);
  return replaced(text, "LIMITS", limits);
}

// 1-based line and column of the first `needle`'s value (after "= ").
std::string where(std::string_view text, std::string_view needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n' ? 1 : 0;
  const auto start = text.rfind('\n', at) + 1;
  const auto value = text.find("= ", at) + 2;
  return ":" + std::to_string(line) + ":" + std::to_string(value - start + 1) + ": ";
}

// The simulated rig at 0 kg, as `hsa-analyze identify --set` writes it.
control::PlantSet simulated_rig() {
  control::PlantSet s;
  for (const control::IdentifiedPlant& p : control::kTableA3) {
    if (p.load_kg != 0) continue;
    control::PlantSetEntry e;
    e.name = "run-" + std::to_string(p.position_mm) + "mm.csv@0kg";
    e.position_m = p.position_m();
    e.b0_per_s2 = {p.b0, 0.0};
    e.b1_per_s = {p.b1, 0.0};
    e.k01_m_s = {p.k01 * 1e-3, 0.0};
    e.k01_retracting_m_s = {p.k01 * 1e-3, 0.0};
    e.kp_per_m = 200.0;
    e.fit_index = 0.95;
    s.plants.push_back(e);
  }
  s.supply_pressure_pa = 25e5;
  s.pump_flow_m3_per_s = 5.0 / 60000;
  s.piston_area_m2 = 4.908738521234052e-4;
  s.area_ratio = 0.7696;
  s.capability.margin = 0.7;
  s.capability.extend = {0.170, 11.8, true, false, 0.7 * 0.170, 0.7 * 11.8, "run-150mm.csv@0kg", 0.0};
  s.capability.retract = {0.206, 12.1, false, false, 0.7 * 0.206, 0.7 * 12.1, "run-150mm.csv@0kg", 0.0};
  return s;
}

// A folder with the simulated rig's plants.toml, where each test writes its hsad.toml.
class CapabilityConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hsa_test_capability_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream out(dir_ / "plants.toml");
    plant_set::write_plant_set(out, simulated_rig());
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `text` as hsad.toml in the folder, loaded as hsad loads it.
  DaemonConfig load(const std::string& text) {
    std::ofstream(dir_ / "hsad.toml") << text;
    return load_config(dir_ / "hsad.toml");
  }
  std::string error_of(const std::string& text) {
    try {
      (void)load(text);
    } catch (const io::ConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "loading did not throw";
    return {};
  }
  [[nodiscard]] std::string file(std::string_view name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

TEST_F(CapabilityConfig, AMaxSpeedOverTheSlowerDirectionIsRefusedNamingItAndThePlantSet) {
  const std::string text = config("plants.toml", "0.15");  // hsad-sim.toml's: over 0.119 extending
  EXPECT_EQ(error_of(text), file("hsad.toml") + where(text, "max_speed_m_s") +
                                "axes[0].pi.max_speed_m_s: expected at most 0.119 m/s, what the plant can follow "
                                "extending (capability.extend.speed_limit_m_s of " +
                                file("plants.toml") + "), got 0.15");
}

TEST_F(CapabilityConfig, AMaxAccelerationOverTheWeakerDirectionIsRefusedNamingItAndThePlantSet) {
  const std::string text = config("plants.toml", "0.1", "max_accel_m_s2 = 8.3");  // over 8.26 extending
  EXPECT_EQ(error_of(text), file("hsad.toml") + where(text, "max_accel_m_s2") +
                                "axes[0].limits.max_accel_m_s2: expected at most 8.26 m/s², what the plant can "
                                "follow extending (capability.extend.acceleration_limit_m_s2 of " +
                                file("plants.toml") + "), got 8.3");
}

// Within both directions' limits: accepted, the capability goes to the axis, and an unset
// max_accel_m_s2 stays derived from the speed (0.118 m/s in 0.1 s: 1.18 m/s², under 8.26).
TEST_F(CapabilityConfig, BoundsWithinTheCapabilityAreAcceptedAndAnUnsetAccelerationStaysDerived) {
  const DaemonConfig c = load(config("plants.toml", "0.118"));
  const AxisConfig& a = c.axes[0];
  EXPECT_EQ(a.limits.max_accel_m_s2, 0.0);
  EXPECT_DOUBLE_EQ(a.capability.extend.speed_m_s, 0.7 * 0.170);
  EXPECT_DOUBLE_EQ(a.capability.extend.accel_m_s2, 0.7 * 11.8);
  EXPECT_DOUBLE_EQ(a.capability.retract.speed_m_s, 0.7 * 0.206);
  EXPECT_DOUBLE_EQ(a.capability.retract.accel_m_s2, 0.7 * 12.1);
  EXPECT_EQ(a.capability_source, file("plants.toml"));
  EXPECT_THAT(describe(c), HasSubstr("capability    extending 0.119 m/s, 8.26 m/s²; retracting 0.1442 m/s, 8.47 m/s² (" +
                                     file("plants.toml") + ")"));
  EXPECT_THAT(describe(c), HasSubstr("moves         max acceleration max speed reached in 0.1 s"));

  const DaemonConfig set = load(config("plants.toml", "0.1", "max_accel_m_s2 = 2.0\nmax_jerk_m_s3 = 40.0"));
  EXPECT_DOUBLE_EQ(set.axes[0].limits.max_accel_m_s2, 2.0);  // a configured one within it is kept
  EXPECT_DOUBLE_EQ(set.axes[0].limits.max_jerk_m_s3, 40.0);
}

// Without a plant set the configured bounds are the only ones, as before: 0.2 m/s, which the
// simulated rig cannot follow extending, is accepted, and the acceleration stays unset (derived).
TEST_F(CapabilityConfig, WithoutAPlantSetTheConfiguredBoundsAloneCount) {
  const DaemonConfig c = load(config("", "0.2"));
  const AxisConfig& a = c.axes[0];
  EXPECT_EQ(a.limits.max_accel_m_s2, 0.0);
  EXPECT_TRUE(std::isinf(a.capability.extend.speed_m_s));
  EXPECT_TRUE(std::isinf(a.capability.retract.accel_m_s2));
  EXPECT_EQ(a.capability_source, "");
  EXPECT_THAT(describe(c), Not(HasSubstr("    capability    ")));
  EXPECT_THAT(describe(c), HasSubstr("moves         max acceleration max speed reached in 0.1 s"));
}

// Where the derived acceleration is more than the plant can follow, the unset max_accel_m_s2 is
// lowered to the weaker direction's limit: a plant set whose limits are 0.5 m/s² against the
// speed's 1.0 m/s².
TEST_F(CapabilityConfig, AnUnsetAccelerationOverTheWeakerLimitIsLoweredToIt) {
  control::PlantSet weak = simulated_rig();
  weak.capability.extend.acceleration_limit_m_s2 = 0.5;
  weak.capability.extend.max_acceleration_m_s2 = 0.5 / 0.7;
  weak.capability.retract.acceleration_limit_m_s2 = 0.6;
  weak.capability.retract.max_acceleration_m_s2 = 0.6 / 0.7;
  {
    std::ofstream out(dir_ / "weak.toml");
    plant_set::write_plant_set(out, weak);
  }
  const DaemonConfig c = load(config("weak.toml", "0.1"));
  EXPECT_DOUBLE_EQ(c.axes[0].limits.max_accel_m_s2, 0.5);
  EXPECT_THAT(describe(c), HasSubstr("moves         max acceleration 0.5 m/s²"));
}

// The custom rig's identified set retracts slower and weaker than it extends (0.0914 m/s,
// 7.06 m/s² against 0.105 m/s, 8.10 m/s²): the message names retracting.
TEST_F(CapabilityConfig, TheCustomRigsSetRefusesNamingRetracting) {
  const std::string set = std::string(HSA_SOURCE_DIR) + "/tests/daemon/data/custom-rig-plants.toml";
  const std::string speed = config(set, "0.1", "", "120.0");  // hsad-sim-custom-rig.toml's speed
  EXPECT_EQ(error_of(speed), file("hsad.toml") + where(speed, "max_speed_m_s") +
                                 "axes[0].pi.max_speed_m_s: expected at most 0.09137842756 m/s, what the plant "
                                 "can follow retracting (capability.retract.speed_limit_m_s of " +
                                 set + "), got 0.1");
  const std::string accel = config(set, "0.09", "max_accel_m_s2 = 7.5", "120.0");
  EXPECT_THAT(error_of(accel), HasSubstr("axes[0].limits.max_accel_m_s2: expected at most 7.056949882 m/s², what the "
                                         "plant can follow retracting (capability.retract.acceleration_limit_m_s2 of " +
                                         set + "), got 7.5"));
  const DaemonConfig c = load(config(set, "0.09", "", "120.0"));
  EXPECT_EQ(c.axes[0].limits.max_accel_m_s2, 0.0);  // 0.9 m/s² derived, under 7.06: left derived
}

}  // namespace
}  // namespace hsa::daemon
