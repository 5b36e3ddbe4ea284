// `hsa-analyze experiment valve --valve FILE`: the valve file is read by the sim plugin's reader
// (drivers/sim/rig_settings.hpp), keys left out keep the paper's values, and a bad file is refused
// with its file, line and key, and what was expected.
#include <gtest/gtest.h>

#include <string>

#include "drivers/config_error.hpp"
#include "tools/hsa_analyze/valve_file.hpp"

namespace {

using hsa::analyze::parse_valve_file;
using hsa::sim::ProportionalValveParameters;

std::string refusal(const std::string& text) {
  try {
    (void)parse_valve_file(text, "variant.toml");
  } catch (const hsa::io::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ValveFile, ReadsTheVariantAndKeepsThePapersValuesElsewhere) {
  const ProportionalValveParameters v = parse_valve_file(
      "[rig.proportional_valve]\nhysteresis_width_a = 0.5\nnatural_frequency_hz = 40.0\ncurrent_max_a = 2.5\n",
      "variant.toml");
  EXPECT_EQ(v.hysteresis_width_a, 0.5);
  EXPECT_EQ(v.natural_frequency_hz, 40.0);
  EXPECT_EQ(v.current_max_a, 2.5);
  ProportionalValveParameters expected;
  expected.hysteresis_width_a = 0.5;
  expected.natural_frequency_hz = 40.0;
  expected.current_max_a = 2.5;
  EXPECT_EQ(v, expected);
  EXPECT_EQ(parse_valve_file("", "empty.toml"), ProportionalValveParameters{});
}

TEST(ValveFile, RefusesOutOfBoundsUnknownAndInconsistent) {
  const std::string bounds = refusal("[rig.proportional_valve]\ncurrent_max_a = 25.0\n");
  EXPECT_NE(bounds.find("variant.toml:2:"), std::string::npos) << bounds;
  EXPECT_NE(bounds.find("rig.proportional_valve.current_max_a"), std::string::npos) << bounds;
  const std::string typo = refusal("[rig.proportional_valve]\nhysteresis_width = 0.5\n");
  EXPECT_NE(typo.find("hysteresis_width"), std::string::npos) << typo;
  EXPECT_NE(typo.find("variant.toml:2:"), std::string::npos) << typo;
  // The experiments run the valve alone: another group of the rig is refused, not ignored.
  const std::string other = refusal("[rig.lvdt]\nbandwidth_hz = 300.0\n");
  EXPECT_NE(other.find("lvdt"), std::string::npos) << other;
  const std::string top = refusal("valve = \"proportional\"\n");
  EXPECT_NE(top.find("valve"), std::string::npos) << top;
  // A dead band that leaves the current no room to open the valve fully.
  const std::string band = refusal("[rig.proportional_valve]\nhysteresis_width_a = 2.0\n");
  EXPECT_NE(band.find("rig.proportional_valve.hysteresis_width_a"), std::string::npos) << band;
  EXPECT_NE(band.find("open fully"), std::string::npos) << band;
  const std::string syntax = refusal("[rig.proportional_valve\n");
  EXPECT_NE(syntax.find("variant.toml:1:"), std::string::npos) << syntax;
}

}  // namespace
