// The gpiod plugin's settings: what a valid table becomes, and that every mistake is refused with
// a message naming the key and what was expected. The last tests load the real plugin and
// configure it on this machine, which has GPIO or not: either way the error must say why.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "drivers/gpiod/gpiod_settings.hpp"
#include "drivers/plugin_error.hpp"
#include "drivers/plugin_loader.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::io::gpiod {
namespace {

using ::testing::HasSubstr;

std::string error_of(const std::string& text) {
  try {
    (void)parse_gpiod_settings(toml::parse(text));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(accepted)";
}

// One channel with the given extra keys, on the top-level chip.
std::string one(const std::string& keys) {
  return "chip = \"gpiochip0\"\n[[channels]]\n" + keys;
}

TEST(GpiodSettings, ParsesNamesOffsetsActiveLowAndSafeValues) {
  const GpiodSettings s = parse_gpiod_settings(toml::parse(R"(
    chip = "gpiochip0"
    [[channels]]
    name = "estop"
    kind = "digital_input"
    line = "hsa-estop"
    active_low = true
    edge_events = true
    bias = "pull_up"
    [[channels]]
    name = "limit_low"
    kind = "digital_input"
    chip = "/dev/gpiochip1"
    line = 3
    [[channels]]
    name = "valve_enable"
    kind = "digital_output"
    line = "hsa-valve-enable"
    safe_value = false
    [[channels]]
    name = "brake_release"
    kind = "digital_output"
    chip = "gpio-sim.0-node0"
    line = 7
    active_low = true
    drive = "open_drain"
    safe_value = true
  )"));
  ASSERT_EQ(s.channels.size(), 4u);
  const LineChannel& estop = s.channels[0];
  EXPECT_EQ(estop.info.name, "estop");
  EXPECT_EQ(estop.info.kind, ChannelKind::digital_input);
  EXPECT_EQ(estop.info.unit, "1");
  EXPECT_EQ(estop.address.chip, "gpiochip0");  // the top-level default
  EXPECT_EQ(estop.address.chip_key, "chip");
  EXPECT_TRUE(estop.address.by_name);
  EXPECT_EQ(estop.address.name, "hsa-estop");
  EXPECT_EQ(estop.address.line_key, "channels[0].line");
  EXPECT_TRUE(estop.active_low);
  EXPECT_TRUE(estop.edge_events);
  EXPECT_EQ(estop.bias, Bias::pull_up);

  const LineChannel& limit = s.channels[1];
  EXPECT_EQ(limit.address.chip, "/dev/gpiochip1");  // overridden per channel
  EXPECT_EQ(limit.address.chip_key, "channels[1].chip");
  EXPECT_FALSE(limit.address.by_name);
  EXPECT_EQ(limit.address.offset, 3u);
  EXPECT_FALSE(limit.active_low);
  EXPECT_FALSE(limit.edge_events);
  EXPECT_EQ(limit.bias, Bias::as_is);
  EXPECT_EQ(limit.address.describe(), "line 3");

  EXPECT_EQ(s.channels[2].info.kind, ChannelKind::digital_output);
  EXPECT_FALSE(s.channels[2].safe_value);
  EXPECT_EQ(s.channels[2].drive, Drive::push_pull);
  EXPECT_EQ(s.channels[2].address.describe(), "line 'hsa-valve-enable'");

  EXPECT_TRUE(s.channels[3].safe_value);
  EXPECT_TRUE(s.channels[3].active_low);
  EXPECT_EQ(s.channels[3].drive, Drive::open_drain);
  EXPECT_EQ(s.channels[3].address.chip, "gpio-sim.0-node0");
}

TEST(GpiodSettings, RequiresChannelsAndTheirKeys) {
  EXPECT_THAT(error_of("chip = \"gpiochip0\"\n"), HasSubstr("channels: required key is missing"));
  EXPECT_THAT(error_of("channels = []\n"), HasSubstr("channels: expected a non-empty array of tables"));
  EXPECT_THAT(error_of("channels = [1]\n"), HasSubstr("channels[0]: expected a table, got 1"));
  EXPECT_THAT(error_of(one("kind = \"digital_input\"\nline = 0\n")),
              HasSubstr("channels[0].name: required key is missing"));
  EXPECT_THAT(error_of(one("name = \"a\"\nline = 0\n")), HasSubstr("channels[0].kind: required key is missing"));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\n")),
              HasSubstr("channels[0].line: required key is missing"));
  EXPECT_THAT(error_of(one("name = \"\"\nkind = \"digital_input\"\nline = 0\n")),
              HasSubstr("channels[0].name: expected a non-empty string"));
}

TEST(GpiodSettings, AChannelNeedsAChip) {
  EXPECT_THAT(error_of("[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = 0\n"),
              HasSubstr("channels[0].chip: required key is missing, expected a GPIO chip name like \"gpiochip0\", a /dev path, a label or a number (here or as the top-level chip)"));
  EXPECT_THAT(error_of("chip = \"\"\n[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = 0\n"),
              HasSubstr("chip: expected a GPIO chip name, /dev path, label or number, got \"\""));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = 0\nchip = 0\n")),
              HasSubstr("channels[0].chip: expected a GPIO chip name like \"gpiochip0\", a /dev path, a label or a number (here or as the top-level chip), got 0"));
}

TEST(GpiodSettings, KindAndLineMustBeValid) {
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"analog_input\"\nline = 0\n")),
              HasSubstr("channels[0].kind: expected \"digital_input\" or \"digital_output\", got \"analog_input\""));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = -1\n")),
              HasSubstr("channels[0].line: expected a line name (string) or offset (integer >= 0), got -1"));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = 1.5\n")),
              HasSubstr("channels[0].line: expected a line name (string) or offset (integer >= 0), got 1.5"));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = \"\"\n")),
              HasSubstr("channels[0].line: expected a line name (string) or offset (integer >= 0), got \"\""));
}

TEST(GpiodSettings, OptionsAreCheckedAndBelongToTheirKind) {
  const std::string in = "name = \"a\"\nkind = \"digital_input\"\nline = 0\n";
  const std::string out = "name = \"a\"\nkind = \"digital_output\"\nline = 0\n";
  EXPECT_THAT(error_of(one(in + "active_low = 1\n")),
              HasSubstr("channels[0].active_low: expected true or false, got 1"));
  EXPECT_THAT(error_of(one(in + "bias = \"up\"\n")),
              HasSubstr("channels[0].bias: expected \"as_is\", \"disable\", \"pull_up\" or \"pull_down\", got \"up\""));
  EXPECT_THAT(error_of(one(out + "drive = \"totem\"\n")),
              HasSubstr("channels[0].drive: expected \"push_pull\", \"open_drain\" or \"open_source\""));
  EXPECT_THAT(error_of(one(out + "safe_value = \"off\"\n")),
              HasSubstr("channels[0].safe_value: expected true or false, got \"off\""));
  // An input has no safe value and an output no edge events: a misplaced key is an error.
  EXPECT_THAT(error_of(one(in + "safe_value = true\n")),
              HasSubstr("channels[0].safe_value: unknown key, expected one of: name, kind, chip, line, "
                        "active_low, bias, edge_events"));
  EXPECT_THAT(error_of(one(out + "edge_events = true\n")),
              HasSubstr("channels[0].edge_events: unknown key"));
  EXPECT_THAT(error_of(one(in + "activelow = true\n")), HasSubstr("channels[0].activelow: unknown key"));
  EXPECT_THAT(error_of("chips = \"x\"\n"), HasSubstr("chips: unknown key, expected one of: chip, channels"));
}

TEST(GpiodSettings, AChargePumpIsAnOutputWithADivisorAndAnEnable) {
  // A valve enable first: every pump below is enabled by it.
  const std::string enable = "name = \"valve_enable\"\nkind = \"digital_output\"\nline = 1\n[[channels]]\n";
  const std::string out = enable + "name = \"pump\"\nkind = \"digital_output\"\nline = 0\n";
  const std::string by = "enabled_by = [\"valve_enable\"]\n";
  const GpiodSettings plain = parse_gpiod_settings(toml::parse(one(out)));
  EXPECT_FALSE(plain.channels[1].charge_pump);
  EXPECT_EQ(plain.channels[1].divisor, 1u);
  EXPECT_TRUE(plain.channels[1].enabled_by.empty());
  const GpiodSettings pump = parse_gpiod_settings(toml::parse(one(out + "charge_pump = true\n" + by)));
  EXPECT_TRUE(pump.channels[1].charge_pump);
  EXPECT_EQ(pump.channels[1].divisor, 1u);  // every write()
  EXPECT_EQ(pump.channels[1].enabled_by, std::vector<std::size_t>{0});
  const GpiodSettings slow =
      parse_gpiod_settings(toml::parse(one(out + "charge_pump = true\ndivisor = 5\nsafe_value = true\n" + by)));
  EXPECT_TRUE(slow.channels[1].charge_pump);
  EXPECT_EQ(slow.channels[1].divisor, 5u);
  EXPECT_TRUE(slow.channels[1].safe_value);
  // Two axes' enables, one declared after the pump: both must be on.
  const GpiodSettings two = parse_gpiod_settings(toml::parse(one(
      out + "charge_pump = true\nenabled_by = [\"valve_enable\", \"y_enable\"]\n"
            "[[channels]]\nname = \"y_enable\"\nkind = \"digital_output\"\nline = 2\n")));
  EXPECT_EQ(two.channels[1].enabled_by, (std::vector<std::size_t>{0, 2}));

  EXPECT_THAT(error_of(one(out + "charge_pump = \"yes\"\n")),
              HasSubstr("channels[1].charge_pump: expected true or false, got \"yes\""));
  EXPECT_THAT(error_of(one(out + "charge_pump = true\ndivisor = 0\n" + by)),
              HasSubstr("channels[1].divisor: expected an integer in [1, 1000000], got 0"));
  EXPECT_THAT(error_of(one(out + "charge_pump = true\ndivisor = 2.5\n" + by)),
              HasSubstr("channels[1].divisor: expected an integer in [1, 1000000], got 2.5"));
  EXPECT_THAT(error_of(one(out + "divisor = 2\n")),
              HasSubstr("channels[1].divisor: expected no divisor on a line that is not a charge pump (set charge_pump = true, or remove it), got 2"));
  EXPECT_THAT(error_of(one(out + "charge_pump = false\ndivisor = 2\n")),
              HasSubstr("channels[1].divisor: expected no divisor on a line that is not a charge pump (set charge_pump = true, or remove it), got 2"));
  // An input cannot be a charge pump.
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = 0\ncharge_pump = true\n")),
              HasSubstr("channels[0].charge_pump: unknown key"));
}

// A pump that toggles whatever the axes do keeps the relay closed through a fault: its enable is
// required, and must name outputs that hsad writes.
TEST(GpiodSettings, AChargePumpNeedsAnEnableOfOtherOutputs) {
  const std::string enable = "name = \"valve_enable\"\nkind = \"digital_output\"\nline = 1\n[[channels]]\n";
  const std::string pump = enable + "name = \"pump\"\nkind = \"digital_output\"\nline = 0\ncharge_pump = true\n";
  EXPECT_THAT(error_of(one(pump)),
              HasSubstr("channels[1].enabled_by: required key is missing, expected a non-empty array of the names of "
                        "this driver's digital outputs that must be on for the charge pump to toggle"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = []\n")), HasSubstr("channels[1].enabled_by: expected a non-empty array"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = \"valve_enable\"\n")),
              HasSubstr("channels[1].enabled_by: expected a non-empty array"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = [1]\n")), HasSubstr("channels[1].enabled_by: expected a non-empty array"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = [\"valve_enabel\"]\n")),
              HasSubstr("channels[1].enabled_by: expected names of this driver's channels; there is no channel "
                        "'valve_enabel'"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = [\"pump\"]\n")),
              HasSubstr("channels[1].enabled_by: expected digital outputs that are not charge pumps; 'pump' is a "
                        "charge pump"));
  EXPECT_THAT(error_of(one(pump + "enabled_by = [\"estop\"]\n[[channels]]\nname = \"estop\"\n"
                                  "kind = \"digital_input\"\nline = 2\n")),
              HasSubstr("'estop' is an input"));
  EXPECT_THAT(error_of(one(enable + "name = \"lamp\"\nkind = \"digital_output\"\nline = 0\n"
                                    "enabled_by = [\"valve_enable\"]\n")),
              HasSubstr("channels[1].enabled_by: expected no enabled_by on a line that is not a charge pump"));
}

TEST(GpiodSettings, NamesAndLinesAreUnique) {
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = 0\n"
                           "[[channels]]\nname = \"a\"\nkind = \"digital_input\"\nline = 1\n")),
              HasSubstr("channels[1].name: expected a name no other channel has (channels[0] is already called \"a\"), got \"a\""));
  EXPECT_THAT(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = \"x\"\n"
                           "[[channels]]\nname = \"b\"\nkind = \"digital_output\"\nline = \"x\"\n")),
              HasSubstr("channels[1].line: expected a line no other channel uses (channels[0], a, has "
                        "line 'x' of chip 'gpiochip0'), got \"x\""));
  // The same offset on two different chips is two lines.
  EXPECT_EQ(error_of(one("name = \"a\"\nkind = \"digital_input\"\nline = 2\n"
                         "[[channels]]\nname = \"b\"\nkind = \"digital_input\"\nline = 2\nchip = \"gpiochip1\"\n")),
            "(accepted)");
}

// The example configuration shipped in systemd/ is accepted by this parser (hsad --check-config
// checks the rest of the file but leaves the plugin's own table to the plugin).
TEST(GpiodSettings, TheShippedExampleParses) {
  const toml::table config = toml::parse_file(HSA_GPIOD_EXAMPLE);
  const toml::table* settings = nullptr;
  for (const toml::node& node : *config["drivers"].as_array()) {
    const toml::table& driver = *node.as_table();
    if (driver["plugin"].value_or(std::string()) == "gpiod") settings = driver["settings"].as_table();
  }
  ASSERT_NE(settings, nullptr) << "no [[drivers]] with plugin = \"gpiod\" in " << HSA_GPIOD_EXAMPLE;
  const GpiodSettings s = parse_gpiod_settings(*settings);
  ASSERT_EQ(s.channels.size(), 5u);
  EXPECT_EQ(s.channels[0].info.name, "estop");
  EXPECT_TRUE(s.channels[0].edge_events);
  EXPECT_TRUE(s.channels[0].active_low);
  EXPECT_EQ(s.channels[0].bias, Bias::pull_down);
  EXPECT_EQ(s.channels[1].info.name, "valve_enable");
  EXPECT_FALSE(s.channels[1].safe_value);
  EXPECT_FALSE(s.channels[1].charge_pump);
  EXPECT_EQ(s.channels[3].info.name, "charge_pump");
  EXPECT_TRUE(s.channels[3].charge_pump);
  EXPECT_EQ(s.channels[3].divisor, 5u);
  EXPECT_EQ(s.channels[3].enabled_by, std::vector<std::size_t>{1});  // the valve enable
}

bool machine_has_gpio() {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    if (entry.path().filename().string().rfind("gpiochip", 0) == 0) return true;
  }
  return false;
}

std::string configure_error(const std::string& settings) {
  try {
    (void)PluginLoader({HSA_PLUGIN_DIR}).load_driver("gpio", "gpiod", toml::parse(settings));
  } catch (const PluginError& e) {
    EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
    return e.what();
  }
  return "(configured)";
}

// The real plugin, asked for a chip that does not exist. On a machine without GPIO (this
// project's build machine) the message must say that the kernel has no GPIO at all; on one with
// GPIO it must list the chips there are. Both name the setting key.
TEST(GpiodPlugin, AMissingChipNamesTheKeyAndSaysWhy) {
  const std::string error = configure_error(R"(
    chip = "hsa-no-such-chip"
    [[channels]]
    name = "estop"
    kind = "digital_input"
    line = "hsa-estop"
    edge_events = true
  )");
  EXPECT_THAT(error, HasSubstr("chip: no GPIO chip 'hsa-no-such-chip'"));
  if (machine_has_gpio()) {
    EXPECT_THAT(error, HasSubstr("Present: "));
  } else {
    EXPECT_THAT(error, HasSubstr("this kernel has no GPIO character device (/dev/gpiochip* does not exist)"));
  }
}

TEST(GpiodPlugin, TheChipKeyNamedIsTheOneTheChannelUsed) {
  const std::string error = configure_error(R"(
    [[channels]]
    name = "valve_enable"
    kind = "digital_output"
    chip = "hsa-no-such-chip"
    line = 1
  )");
  EXPECT_THAT(error, HasSubstr("channels[0].chip: no GPIO chip 'hsa-no-such-chip'"));
}

TEST(GpiodPlugin, SettingErrorsComeBeforeAnyGpioAccess) {
  EXPECT_THAT(configure_error("chip = \"gpiochip0\"\n"), HasSubstr("channels: required key is missing"));
}

}  // namespace
}  // namespace hsa::io::gpiod
