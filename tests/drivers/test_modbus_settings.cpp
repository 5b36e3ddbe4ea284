// The modbus plugin's settings: what a valid table becomes, and that every mistake is refused
// with a message naming the key and what was expected. The last tests load the real plugin.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <toml++/toml.h>

#include "drivers/modbus/modbus_settings.hpp"
#include "drivers/plugin_error.hpp"
#include "drivers/plugin_loader.hpp"
#include "drivers/table_reader.hpp"
#include "tests/drivers/test_modbus_support.hpp"

namespace hsa::io::modbus {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

const std::string tcp = "transport = \"tcp\"\nport = 1502\n";

std::string error_of(const std::string& text) {
  try {
    (void)parse_modbus_settings(toml::parse(text));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ModbusSettings, ParsesLinkAndChannels) {
  const ModbusSettings s = parse_modbus_settings(toml::parse(tcp + R"(
    host = "localhost"
    poll_period_s = 0.002
    response_timeout_s = 0.02
    max_age_s = 0.03
    word_order = "low_first"
    [[channels]]
    name = "p"
    kind = "analog_input"
    table = "input_register"
    address = 4
    type = "float32"
    unit = "Pa"
    [[channels]]
    name = "u"
    kind = "analog_output"
    table = "holding_register"
    address = 0
    type = "int32"
    word_order = "high_first"
    scale = 0.001
    offset = 1
    safe_value = 0.5
    [[channels]]
    name = "en"
    kind = "digital_output"
    table = "coil"
    address = 3
    safe_value = true
  )"));
  EXPECT_EQ(s.link.describe(), "Modbus TCP localhost:1502");
  EXPECT_EQ(s.link.poll_period, 2ms);
  EXPECT_EQ(s.link.response_timeout, 20ms);
  ASSERT_EQ(s.channels.size(), 3u);
  EXPECT_EQ(s.channels[0].order, WordOrder::low_first);  // the default from the top level
  EXPECT_EQ(s.channels[0].max_age, 30ms);
  EXPECT_EQ(s.channels[0].width(), 2);
  EXPECT_EQ(s.channels[0].info.unit, "Pa");
  EXPECT_EQ(s.channels[1].order, WordOrder::high_first);  // overridden per channel
  EXPECT_EQ(s.channels[1].scale, 0.001);
  EXPECT_EQ(s.channels[1].safe_value, 0.5);
  EXPECT_EQ(s.channels[2].table, Table::coil);
  EXPECT_EQ(s.channels[2].safe_value, 1.0);
}

TEST(ModbusSettings, OutputTimeoutDefaultsToFiveMillisecondsAndIsChecked) {
  const std::string out = "[[channels]]\nname = \"u\"\nkind = \"analog_output\"\ntable = \"holding_register\"\naddress = 0\n";
  EXPECT_EQ(parse_modbus_settings(toml::parse(tcp + out)).link.output_timeout, 5ms);
  EXPECT_EQ(parse_modbus_settings(toml::parse(tcp + "output_timeout_s = 0.02\n" + out)).link.output_timeout, 20ms);
  EXPECT_THAT(error_of(tcp + "output_timeout_s = 0\n" + out),
              HasSubstr("output_timeout_s: expected a finite number in (0, 60), got 0"));
  EXPECT_THAT(error_of(tcp + "output_timeout_s = 120\n" + out), HasSubstr("output_timeout_s: expected a finite number in (0, 60), got 120"));
}

TEST(ModbusSettings, AHeartbeatIsOnlyForAnUnscaledHoldingRegisterOutput) {
  const auto ch = [](const std::string& kind, const std::string& table, const std::string& more) {
    return "[[channels]]\nname = \"hb\"\nkind = \"" + kind + "\"\ntable = \"" + table +
           "\"\naddress = 3\n" + more;
  };
  const ModbusSettings s =
      parse_modbus_settings(toml::parse(tcp + ch("analog_output", "holding_register", "heartbeat = true\n")));
  EXPECT_TRUE(s.channels[0].heartbeat);
  EXPECT_THAT(error_of(tcp + ch("analog_input", "input_register", "heartbeat = true\n")),
              HasSubstr("channels[0].heartbeat: expected no heartbeat on kind \"analog_input\" (a heartbeat "
                        "is an analog_output in table \"holding_register\"), got true"));
  EXPECT_THAT(error_of(tcp + ch("digital_output", "coil", "heartbeat = true\n")),
              HasSubstr("channels[0].heartbeat: expected no heartbeat on kind \"digital_output\" (a heartbeat is an analog_output in table \"holding_register\"), got true"));
  EXPECT_THAT(error_of(tcp + ch("analog_output", "holding_register", "heartbeat = true\nscale = 0.1\n")),
              HasSubstr("channels[0].heartbeat: expected no scale or offset beside it (a heartbeat counter is written raw), got true"));
  EXPECT_THAT(error_of(tcp + ch("analog_output", "holding_register", "heartbeat = \"yes\"\n")),
              HasSubstr("channels[0].heartbeat: expected true or false, got \"yes\""));
}

TEST(ModbusSettings, RtuNeedsADeviceAndTakesSerialParameters) {
  EXPECT_THAT(error_of("transport = \"rtu\"\n"), HasSubstr("device: required key is missing"));
  const ModbusSettings s = parse_modbus_settings(toml::parse(R"(
    transport = "rtu"
    device = "/dev/ttyUSB0"
    baud = 115200
    parity = "none"
    stop_bits = 2
    unit_id = 17
    [[channels]]
    name = "x"
    kind = "encoder_input"
    table = "input_register"
    address = 0
  )"));
  EXPECT_EQ(s.link.describe(), "Modbus RTU /dev/ttyUSB0");
  EXPECT_EQ(s.link.parity, 'N');
  EXPECT_EQ(s.link.baud, 115200);
  EXPECT_EQ(s.link.unit_id, 17);
  EXPECT_THAT(error_of("transport = \"rtu\"\ndevice = \"/dev/x\"\nparity = \"mark\"\n"),
              HasSubstr("parity: expected \"none\", \"even\" or \"odd\", got \"mark\""));
  EXPECT_THAT(error_of("transport = \"rtu\"\ndevice = \"/dev/x\"\nhost = \"a\"\n"),
              HasSubstr("host: unknown key"));
}

TEST(ModbusSettings, MistakesNameTheKeyAndWhatWasExpected) {
  const std::string ch = "[[channels]]\nname = \"a\"\n";
  EXPECT_THAT(error_of(""), HasSubstr("transport: required key is missing"));
  EXPECT_THAT(error_of("transport = \"udp\""), HasSubstr("transport: expected \"tcp\" or \"rtu\", got \"udp\""));
  EXPECT_THAT(error_of(tcp), HasSubstr("channels: required key is missing"));
  EXPECT_THAT(error_of("transport = \"tcp\"\nport = 70000\n"),
              HasSubstr("port: expected an integer in [1, 65535], got 70000"));
  EXPECT_THAT(error_of(tcp + "unit_id = 250\n"), HasSubstr("unit_id: expected an integer in [1, 247] or 255"));
  EXPECT_THAT(error_of(tcp + "poll_period_s = -1\n"), HasSubstr("poll_period_s: expected a finite number > 0, got -1"));
  EXPECT_THAT(error_of(tcp + "reconnect_min_s = 2\nreconnect_max_s = 1\n"),
              HasSubstr("reconnect_max_s: expected at least reconnect_min_s"));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\n"),
              HasSubstr("channels[0].address: required key is missing"));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"coil\"\naddress = 0\n"),
              HasSubstr("channels[0].table: expected \"input_register\" or \"holding_register\" for "
                        "kind \"analog_input\", got \"coil\""));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_output\"\ntable = \"input_register\"\naddress = 0\n"),
              HasSubstr("channels[0].table: expected \"holding_register\" for kind \"analog_output\""));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\naddress = 0\ntype = \"int64\"\n"),
              HasSubstr("channels[0].type: expected \"int16\", \"uint16\", \"int32\" or \"float32\", got \"int64\""));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\naddress = 0\nword_order = \"big\"\n"),
              HasSubstr("channels[0].word_order: expected \"high_first\" or \"low_first\", got \"big\""));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\naddress = 0\nscale = 0\n"),
              HasSubstr("channels[0].scale: expected a finite, non-zero number, got 0"));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\naddress = 65535\ntype = \"float32\"\n"),
              HasSubstr("channels[0].address: expected an address whose 2 registers end at or below 65535"));
  // Keys that make no sense for the kind are refused, not ignored.
  EXPECT_THAT(error_of(tcp + ch + "kind = \"digital_input\"\ntable = \"discrete_input\"\naddress = 0\nscale = 2\n"),
              HasSubstr("channels[0].scale: unknown key"));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"analog_input\"\ntable = \"input_register\"\naddress = 0\nsafe_value = 1\n"),
              HasSubstr("channels[0].safe_value: unknown key"));
  EXPECT_THAT(error_of(tcp + ch + "kind = \"digital_output\"\ntable = \"coil\"\naddress = 0\nsafe_value = 1\n"),
              HasSubstr("channels[0].safe_value: expected true or false, got 1"));
}

TEST(ModbusSettings, ChannelsMayNotCollide) {
  const std::string a = "[[channels]]\nname = \"a\"\nkind = \"analog_input\"\ntable = \"input_register\"\n"
                        "address = 10\ntype = \"int32\"\n";
  EXPECT_THAT(error_of(tcp + a + "[[channels]]\nname = \"b\"\nkind = \"analog_input\"\n"
                                 "table = \"input_register\"\naddress = 11\n"),
              HasSubstr("channels[1].address: expected an address that does not overlap channels[0] (a) in table input_register, got 11"));
  // The same address in another table is another register.
  EXPECT_EQ(error_of(tcp + a + "[[channels]]\nname = \"b\"\nkind = \"analog_input\"\n"
                               "table = \"holding_register\"\naddress = 11\n"),
            "(accepted)");
  EXPECT_THAT(error_of(tcp + a + "[[channels]]\nname = \"a\"\nkind = \"analog_input\"\n"
                                 "table = \"input_register\"\naddress = 20\n"),
              HasSubstr("channels[1].name: expected a name no other channel has (channels[0] is already called \"a\"), got \"a\""));
  EXPECT_THAT(error_of(tcp + "[[channels]]\nname = \"link_up\"\nkind = \"digital_input\"\n"
                             "table = \"discrete_input\"\naddress = 0\n"),
              HasSubstr("channels[0].name: expected a name other than \"link_up\", a status channel the driver declares itself, got \"link_up\""));
}

TEST(ModbusPlugin, ConfigureFailsWithTheLinkAndReasonWhenNobodyListens) {
  const int port = modbus_test::free_tcp_port();  // just released: nothing listens there
  const std::string settings = "transport = \"tcp\"\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) +
                               "\n[[channels]]\nname = \"x\"\nkind = \"analog_input\"\n"
                               "table = \"input_register\"\naddress = 0\n";
  try {
    (void)PluginLoader({HSA_PLUGIN_DIR}).load_driver("io", "modbus", toml::parse(settings));
    FAIL() << "configure succeeded with nobody listening";
  } catch (const PluginError& e) {
    EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
    EXPECT_THAT(e.what(), HasSubstr("cannot connect to Modbus TCP 127.0.0.1:" + std::to_string(port) +
                                    ": Connection refused"));
  }
}

TEST(ModbusPlugin, SettingErrorsReachTheLoader) {
  try {
    (void)PluginLoader({HSA_PLUGIN_DIR}).load_driver("io", "modbus", toml::parse("transport = \"tcp\"\nbaud = 9600\n"));
    FAIL() << "configure accepted an RTU key on TCP";
  } catch (const PluginError& e) {
    EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
    EXPECT_THAT(e.what(), HasSubstr("baud: unknown key"));
  }
}

}  // namespace
}  // namespace hsa::io::modbus
