// The plant-set file (plant_set/plant_set_file.hpp): what the writer writes the reader gives back
// exactly, and every kind of bad input is refused with file:line:column, the key and what was
// expected.
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "drivers/config_error.hpp"
#include "plant_set/plant_set_file.hpp"

namespace hsa::plant_set {
namespace {

control::PlantSet two_plants() {
  control::PlantSet s;
  control::PlantSetEntry a;
  a.name = "run-0kg.csv@0kg";
  a.position_m = 0.1503;
  a.load_kg = 0.0;
  a.b0_per_s2 = {11643.25, 61.5};
  a.b1_per_s = {107.53, 0.81};
  a.k01_m_s = {0.23371, 0.0012};
  a.k01_retracting_m_s = {0.2093, 0.0017};
  a.delay_s = 0.55e-3;
  a.kp_per_m = 200.0;
  a.fit_index = 0.914;
  a.nominal_score = 8.348;
  control::PlantSetEntry b = a;
  b.name = "run \"6\".csv@6.5kg";  // a quote in the name must survive
  b.load_kg = 6.5;
  b.b0_per_s2.value = 7829.1 / 3.0;  // a number with all 17 digits
  s.plants = {a, b};
  s.nominal = 1;
  s.supply_pressure_pa = 25e5;
  s.pump_flow_m3_per_s = 5.0 / 60000;
  s.piston_area_m2 = 4.908738521234052e-4;
  s.area_ratio = 0.7696;
  s.capability.margin = 0.7;
  s.capability.extend = {0.1698, 8.99, true, false, 0.7 * 0.1698, 0.7 * 8.99, "run-0kg.csv@0kg", 0.0};
  s.capability.retract = {0.1943, 9.25, false, false, 0.7 * 0.1943, 0.7 * 9.25, b.name, 6.5};
  return s;
}

std::string text_of(const control::PlantSet& s) {
  std::ostringstream out;
  write_plant_set(out, s);
  return out.str();
}

TEST(PlantSetFile, WhatIsWrittenReadsBackExactly) {
  const control::PlantSet s = two_plants();
  const control::PlantSet r = parse_plant_set(text_of(s), "set.toml");
  ASSERT_EQ(r.plants.size(), 2u);
  EXPECT_EQ(r.nominal, 1u);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& w = s.plants[i];
    const auto& g = r.plants[i];
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(g.position_m, w.position_m);
    EXPECT_EQ(g.load_kg, w.load_kg);
    EXPECT_EQ(g.b0_per_s2.value, w.b0_per_s2.value);
    EXPECT_EQ(g.b0_per_s2.std_dev, w.b0_per_s2.std_dev);
    EXPECT_EQ(g.b1_per_s.value, w.b1_per_s.value);
    EXPECT_EQ(g.k01_m_s.value, w.k01_m_s.value);
    EXPECT_EQ(g.k01_m_s.std_dev, w.k01_m_s.std_dev);
    EXPECT_EQ(g.k01_retracting_m_s.value, w.k01_retracting_m_s.value);
    EXPECT_EQ(g.delay_s, w.delay_s);
    EXPECT_EQ(g.kp_per_m, w.kp_per_m);
    EXPECT_EQ(g.fit_index, w.fit_index);
    EXPECT_EQ(g.nominal_score, w.nominal_score);
  }
  EXPECT_EQ(r.piston_area_m2, s.piston_area_m2);
  EXPECT_EQ(r.pump_flow_m3_per_s, s.pump_flow_m3_per_s);
  EXPECT_EQ(r.capability.margin, 0.7);
  EXPECT_EQ(r.capability.extend.max_speed_m_s, s.capability.extend.max_speed_m_s);
  EXPECT_EQ(r.capability.extend.speed_limit_m_s, s.capability.extend.speed_limit_m_s);
  EXPECT_TRUE(r.capability.extend.speed_pump_limited);
  EXPECT_EQ(r.capability.retract.worst_run, s.plants[1].name);
  EXPECT_EQ(r.capability.retract.load_kg, 6.5);
  // The paper's units come back through plant(): gain k01[mm/s]·b0.
  EXPECT_DOUBLE_EQ(r.plants[0].plant().gain, 233.71 * 11643.25);
}

// `edit` replaces the first occurrence of `from` in a good file by `to`; the error must start
// with set.toml:<line>: and name the key and the expectation.
void expect_refused(const std::string& from, const std::string& to, const std::string& words) {
  std::string text = text_of(two_plants());
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from << "\n" << text;
  text.replace(at, from.size(), to);
  // The line the edit lands on (1-based), for the message's location.
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  try {
    (void)parse_plant_set(text, "set.toml");
    ADD_FAILURE() << "accepted: " << to;
  } catch (const io::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("set.toml:", 0), 0u) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
    if (words.find("missing") == std::string::npos && words.find("syntax") == std::string::npos) {
      EXPECT_EQ(what.rfind("set.toml:" + std::to_string(line) + ":", 0), 0u) << what;
    }
  }
}

TEST(PlantSetFile, RefusesBadInputNamingFileLineAndKey) {
  expect_refused("format = \"hsa-plant-set\"", "format = \"hsad\"", "format: expected \"hsa-plant-set\"");
  expect_refused("version = 1", "version = 2", "version: expected");
  expect_refused("nominal = 1", "nominal = 2", "nominal: expected");
  expect_refused("b0_per_s2 = 11643.25", "b0_per_s2 = -11643.25", "plant[0].b0_per_s2: expected a finite number in (0, 1000000000], got -11643.25");
  expect_refused("b1_per_s = 107.53", "b1_per_s = 0", "plant[0].b1_per_s: expected a finite number in (0");
  // k01 in the paper's mm/s by mistake is out of the m/s range.
  expect_refused("k01_m_s = 0.23371", "k01_m_s = 233.71", "plant[0].k01_m_s: expected a finite number in (0, 100]");
  expect_refused("b0_per_s2_std = 61.5", "b0_per_s2_std = -1", "plant[0].b0_per_s2_std: expected");
  expect_refused("position_m = 0.1503", "position_m = nan", "plant[0].position_m: expected");
  expect_refused("load_kg = 6.5\nb0", "load_kg = \"heavy\"\nb0", "plant[1].load_kg: expected a finite number in [0");
  expect_refused("fit_index = 0.914", "fit_index = 1.5", "plant[0].fit_index: expected a finite number in [-100, 1]");
  expect_refused("delay_s = 0.00055", "dealy_s = 0.00055", "dealy_s");
  expect_refused("margin = 0.7", "margin = 0", "capability.margin: expected");
  expect_refused("speed_limit_m_s = 0.11886", "speed_limit_m_s = 0.2",
                 "capability.extend.speed_limit_m_s: expected a finite number in (0, 0.1698]");
  expect_refused("[capability.retract]", "[capability.retrakt]", "capability.retrakt");
  expect_refused("name = \"run \\\"6\\\".csv@6.5kg\"\nposition_m", "name = \"run-0kg.csv@0kg\"\nposition_m",
                 "plant[1].name: expected a name no other plant has");
  expect_refused("area_ratio = 0.7696", "area_ratio = 1.2", "area_ratio: expected");
  expect_refused("version = 1", "version = = 1", "TOML syntax error");
}

TEST(PlantSetFile, RefusesAFileWithoutPlants) {
  std::string text = text_of(two_plants());
  text.resize(text.find("\n[[plant]]"));
  try {
    (void)parse_plant_set(text, "set.toml");
    ADD_FAILURE();
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("plant: required key is missing, expected at least one [[plant]]"),
              std::string::npos)
        << e.what();
  }
}

TEST(PlantSetFile, ANameToolsCannotWriteIsRefusedBeforeWriting) {
  control::PlantSet s = two_plants();
  s.plants[0].name = "tab\there";
  std::ostringstream out;
  EXPECT_THROW(write_plant_set(out, s), std::invalid_argument);
  s = two_plants();
  s.nominal = 2;
  EXPECT_THROW(write_plant_set(out, s), std::invalid_argument);
}

TEST(PlantSetFile, AMissingFileIsNamed) {
  try {
    (void)load_plant_set("/nonexistent/set.toml");
    ADD_FAILURE();
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/set.toml"), std::string::npos);
  }
}

}  // namespace
}  // namespace hsa::plant_set
