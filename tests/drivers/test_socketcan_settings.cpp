// The socketcan plugin's settings: what a valid table becomes, and that every mistake is refused
// with a message naming the key and what was expected.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <linux/can.h>

#include <string>

#include <toml++/toml.h>

#include "drivers/table_reader.hpp"
#include "drivers/socketcan/can_settings.hpp"

namespace hsa::io::socketcan {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

const std::string head = "interface = \"vcan0\"\n";

// An input frame 0x181 of 4 bytes with one 4-byte channel, then whatever `extra` adds.
const std::string encoder_frame = R"(
[[frames]]
id = 0x181
direction = "input"
length = 4
[[frames.channels]]
name = "encoder"
kind = "encoder_input"
byte_offset = 0
bytes = 4
)";

std::string error_of(const std::string& text) {
  try {
    (void)parse_can_settings(toml::parse(text));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(SocketCanSettings, ParsesFramesAndChannels) {
  const CanSettings s = parse_can_settings(toml::parse(head + R"(
    max_frames_per_read = 16
    max_age_s = 0.03
    byte_order = "big_endian"
    [[frames]]
    id = 0x181
    direction = "input"
    length = 6
    [[frames.channels]]
    name = "encoder"
    kind = "encoder_input"
    byte_offset = 0
    bytes = 4
    signed = true
    scale = 1e-6
    unit = "m"
    [[frames.channels]]
    name = "ready"
    kind = "digital_input"
    byte_offset = 5
    [[frames]]
    id = 0x18FF0201
    extended = true
    direction = "output"
    length = 8
    period_s = 0.01
    [[frames.channels]]
    name = "current_cmd"
    kind = "analog_output"
    byte_offset = 2
    bytes = 2
    byte_order = "little_endian"
    scale = 0.001
    offset = 0.5
    unit = "A"
    safe_value = 0.5
    [[frames.channels]]
    name = "enable"
    kind = "digital_output"
    byte_offset = 0
    safe_value = true
  )"));
  EXPECT_EQ(s.interface, "vcan0");
  EXPECT_EQ(s.max_frames_per_read, 16);
  EXPECT_FALSE(s.uses_fd());
  ASSERT_EQ(s.frames.size(), 2u);
  const FrameMap& in = s.frames[0];
  EXPECT_EQ(in.id, 0x181u);
  EXPECT_EQ(in.can_id(), 0x181u);
  EXPECT_EQ(in.direction, Direction::input);
  EXPECT_EQ(in.length, 6);
  EXPECT_EQ(in.max_age, 30ms);  // the default from the top level
  ASSERT_EQ(in.channels.size(), 2u);
  const ChannelMap& encoder = in.channels[0];
  EXPECT_EQ(encoder.info.kind, ChannelKind::encoder_input);
  EXPECT_EQ(encoder.info.unit, "m");
  EXPECT_EQ(encoder.codec.field.size, 4);
  EXPECT_EQ(encoder.codec.field.order, ByteOrder::big_endian);  // the default from the top level
  EXPECT_TRUE(encoder.codec.field.is_signed);
  EXPECT_EQ(encoder.codec.scale, 1e-6);
  EXPECT_TRUE(in.channels[1].codec.digital);
  EXPECT_EQ(in.channels[1].codec.field.size, 1);
  EXPECT_EQ(in.channels[1].codec.field.offset, 5);

  const FrameMap& out = s.frames[1];
  EXPECT_EQ(out.can_id(), 0x18FF0201u | CAN_EFF_FLAG);
  EXPECT_EQ(out.describe(), "frame 0x18FF0201 (extended)");
  EXPECT_EQ(out.period, 10ms);
  EXPECT_EQ(out.channels[0].codec.field.order, ByteOrder::little_endian);  // overridden
  EXPECT_EQ(out.channels[0].codec.offset, 0.5);
  EXPECT_EQ(out.channels[0].safe_value, 0.5);
  EXPECT_EQ(out.channels[1].safe_value, 1.0);
}

TEST(SocketCanSettings, Defaults) {
  const CanSettings s = parse_can_settings(toml::parse(head + encoder_frame));
  EXPECT_EQ(s.max_frames_per_read, 64);
  EXPECT_EQ(s.frames[0].max_age, 100ms);
  EXPECT_EQ(s.frames[0].channels[0].codec.field.order, ByteOrder::little_endian);
  EXPECT_FALSE(s.frames[0].channels[0].codec.field.is_signed);
  EXPECT_EQ(s.frames[0].channels[0].info.unit, "1");
}

TEST(SocketCanSettings, AcceptsCanFdLengths) {
  std::string text = head + encoder_frame;
  text.replace(text.find("length = 4"), 10, "fd = true\nlength = 48");
  const CanSettings s = parse_can_settings(toml::parse(text));
  EXPECT_TRUE(s.uses_fd());
  EXPECT_EQ(s.frames[0].length, 48);
  text.replace(text.find("length = 48"), 11, "length = 40");
  EXPECT_THAT(error_of(text), HasSubstr("frames[0].length: expected a CAN FD payload length"));
}

TEST(SocketCanSettings, TopLevelMistakesNameTheKey) {
  EXPECT_THAT(error_of(encoder_frame), HasSubstr("interface: required key is missing"));
  EXPECT_THAT(error_of("interface = \"\"\n" + encoder_frame),
              HasSubstr("interface: expected a CAN network interface name of 1 to 15 characters, such as \"can0\", got \"\""));
  EXPECT_THAT(error_of("interface = \"a_very_long_name0\"\n" + encoder_frame), HasSubstr("interface"));
  EXPECT_THAT(error_of(head), HasSubstr("frames: required key is missing"));
  EXPECT_THAT(error_of(head + "frames = []\n"), HasSubstr("frames: expected a non-empty array"));
  EXPECT_THAT(error_of(head + "bitrate = 500000\n" + encoder_frame), HasSubstr("bitrate: unknown key"));
  EXPECT_THAT(error_of(head + "max_frames_per_read = 0\n" + encoder_frame),
              HasSubstr("max_frames_per_read: expected an integer in [1, 4096], got 0"));
  EXPECT_THAT(error_of(head + "max_age_s = -1\n" + encoder_frame),
              HasSubstr("max_age_s: expected a finite number > 0, got -1"));
  EXPECT_THAT(error_of(head + "byte_order = \"motorola\"\n" + encoder_frame),
              HasSubstr("byte_order: expected \"little_endian\" or \"big_endian\", got \"motorola\""));
}

// encoder_frame with one line replaced.
std::string with(const std::string& line, const std::string& replacement) {
  std::string text = head + encoder_frame;
  const auto at = text.find(line);
  EXPECT_NE(at, std::string::npos) << line;
  return text.replace(at, line.size(), replacement);
}

TEST(SocketCanSettings, FrameMistakesNameTheKey) {
  EXPECT_THAT(error_of(with("id = 0x181\n", "")), HasSubstr("frames[0].id: required key is missing"));
  EXPECT_THAT(error_of(with("id = 0x181", "id = 0x800")),
              HasSubstr("frames[0].id: expected an 11-bit CAN id in [0, 0x7FF] (set extended = true "
                        "for a 29-bit id), got 0x800"));
  EXPECT_THAT(error_of(with("id = 0x181", "id = 0x20000000\nextended = true")),
              HasSubstr("frames[0].id: expected a 29-bit CAN id in [0, 0x1FFFFFFF]"));
  EXPECT_THAT(error_of(with("id = 0x181", "id = -1")), HasSubstr("frames[0].id: expected an 11-bit"));
  EXPECT_THAT(error_of(with("direction = \"input\"", "direction = \"rx\"")),
              HasSubstr("frames[0].direction: expected \"input\" or \"output\", got \"rx\""));
  EXPECT_THAT(error_of(with("length = 4", "length = 9")),
              HasSubstr("frames[0].length: expected an integer in [1, 8] for a classic frame (set fd = "
                        "true for CAN FD), got 9"));
  EXPECT_THAT(error_of(with("length = 4", "length = 0")), HasSubstr("frames[0].length: expected an integer in [1, 8] for a classic frame (set fd = true for CAN FD), got 0"));
  EXPECT_THAT(error_of(with("length = 4", "length = 4\nperiod_s = 0.01")),
              HasSubstr("frames[0].period_s: unknown key"));  // inputs take max_age_s
  EXPECT_THAT(error_of(with("length = 4", "length = 4\nmax_age_s = 0")),
              HasSubstr("frames[0].max_age_s: expected a finite number > 0, got 0"));
  EXPECT_THAT(error_of(with("length = 4", "length = 4\nfd = 1")),
              HasSubstr("frames[0].fd: expected true or false, got 1"));
  EXPECT_THAT(error_of(head + encoder_frame + encoder_frame),
              HasSubstr("frames[1].id: expected an id no other frame has (frames[0] is 0x181), got 0x181"));
  // The same number as an extended id is another frame.
  std::string two = head + encoder_frame + encoder_frame;
  two.replace(two.rfind("id = 0x181"), 10, "id = 0x181\nextended = true");
  two.replace(two.rfind("name = \"encoder\""), 16, "name = \"encoder2\"");
  EXPECT_EQ(error_of(two), "(accepted)");
}

TEST(SocketCanSettings, ChannelMistakesNameTheKey) {
  EXPECT_THAT(error_of(with("bytes = 4\n", "")), HasSubstr("frames[0].channels[0].bytes: required key is missing"));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 5")),
              HasSubstr("frames[0].channels[0].bytes: expected at most 4 to fit in the frame's 4 bytes "
                        "from byte_offset 0, got 5"));
  EXPECT_THAT(error_of(with("byte_offset = 0", "byte_offset = 2")),
              HasSubstr("frames[0].channels[0].bytes: expected at most 2 to fit in the frame's 4 bytes "
                        "from byte_offset 2, got 4"));
  EXPECT_THAT(error_of(with("byte_offset = 0", "byte_offset = 4")),
              HasSubstr("frames[0].channels[0].byte_offset: expected an integer in [0, 3], got 4"));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 9")),
              HasSubstr("frames[0].channels[0].bytes: expected an integer in [1, 8], got 9"));
  EXPECT_THAT(error_of(with("kind = \"encoder_input\"", "kind = \"analog_output\"")),
              HasSubstr("frames[0].channels[0].kind: expected \"encoder_input\", \"analog_input\" or "
                        "\"digital_input\", got \"analog_output\""));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 4\nsafe_value = 0.0")),
              HasSubstr("frames[0].channels[0].safe_value: unknown key"));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 4\nscale = 0")),
              HasSubstr("frames[0].channels[0].scale: expected a finite, non-zero number, got 0"));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 4\nsigned = \"yes\"")),
              HasSubstr("frames[0].channels[0].signed: expected true or false"));
  EXPECT_THAT(error_of(with("bytes = 4", "bytes = 4\nendianness = \"big\"")),
              HasSubstr("frames[0].channels[0].endianness: unknown key"));
  EXPECT_THAT(error_of(with("name = \"encoder\"", "name = \"bus_off\"")),
              HasSubstr("frames[0].channels[0].name: expected a name other than \"bus_off\", a status "
                        "channel the driver declares itself, got \"bus_off\""));
  EXPECT_THAT(error_of(head + "[[frames]]\nid = 0x181\ndirection = \"input\"\nlength = 4\nchannels = 3\n"),
              HasSubstr("frames[0].channels: expected an array of tables ([[frames.channels]]), got 3"));
}

TEST(SocketCanSettings, ChannelsMayNotOverlapOrRepeatANameOrMissTheDirection) {
  const std::string second = R"(
[[frames.channels]]
name = "status"
kind = "analog_input"
byte_offset = 3
bytes = 1
)";
  EXPECT_THAT(error_of(head + encoder_frame + second),
              HasSubstr("frames[0].channels[1].byte_offset: expected bytes that do not overlap channels[0] "
                        "(encoder, bytes 0..3) with bytes = 1, got 3"));
  std::string out = head + encoder_frame;
  out.replace(out.find("0x181"), 5, "0x201");
  out.replace(out.find("\"input\""), 7, "\"output\"");
  EXPECT_THAT(error_of(out), HasSubstr("frames[0].channels[0].kind: expected \"analog_output\" or "
                                       "\"digital_output\", got \"encoder_input\""));
  std::string twice = head + encoder_frame + encoder_frame;
  twice.replace(twice.rfind("0x181"), 5, "0x182");
  EXPECT_THAT(error_of(twice), HasSubstr("frames[1].channels[0].name: expected a name no other channel "
                                         "has (frame 0x181 has one), got \"encoder\""));
}

TEST(SocketCanSettings, SafeValueMustFitTheField) {
  const std::string out = head + R"(
[[frames]]
id = 0x201
direction = "output"
length = 2
[[frames.channels]]
name = "current_cmd"
kind = "analog_output"
byte_offset = 0
bytes = 2
scale = 0.001
)";
  EXPECT_EQ(error_of(out + "safe_value = 65.535\n"), "(accepted)");
  EXPECT_THAT(error_of(out + "safe_value = 70.0\n"),
              HasSubstr("frames[0].channels[0].safe_value: expected a value the 2-byte unsigned field can "
                        "carry after scale and offset, got 70"));
  EXPECT_THAT(error_of(out + "safe_value = -0.1\n"), HasSubstr("frames[0].channels[0].safe_value"));
  EXPECT_THAT(error_of(out + "period_s = 0.01\n"), HasSubstr("frames[0].channels[0].period_s: unknown key"));
}

// The example in systemd/ is what users copy: its socketcan settings must be valid as shipped.
TEST(SocketCanSettings, TheShippedExampleIsValid) {
  const toml::table config = toml::parse_file(HSA_SOCKETCAN_EXAMPLE);
  const toml::table* settings = nullptr;
  for (const toml::node& d : *config["drivers"].as_array()) {
    if (d.as_table()->get("plugin")->value_or(std::string_view{}) == "socketcan") {
      settings = d.as_table()->get("settings")->as_table();
    }
  }
  ASSERT_NE(settings, nullptr) << "no socketcan driver in " << HSA_SOCKETCAN_EXAMPLE;
  const CanSettings s = parse_can_settings(*settings);
  EXPECT_EQ(s.interface, "vcan0");
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].channels[0].info.name, "encoder");
  EXPECT_EQ(s.frames[1].channels[0].info.name, "valve_cmd");
  EXPECT_EQ(s.frames[1].channels[1].info.name, "valve_enable");
}

}  // namespace
}  // namespace hsa::io::socketcan
