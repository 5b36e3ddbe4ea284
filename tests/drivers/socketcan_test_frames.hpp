// The frame map the socketcan plugin's tests share, so that the host tests of the frame
// bookkeeping and the real-kernel tests check one configuration.
#pragma once

#include <string>

namespace hsa::io::socketcan_test {

// Encoder frame 0x181 in (4 bytes: int32 little-endian, 1 µm; stale after encoder_max_age_s),
// temperature 0x18FF0001 in (extended, 2 bytes: uint16 big-endian, 0.1 °C), current command 0x201
// out every 10 ms (3 bytes: int16 big-endian mA, then a 1-byte enable), safe value -0.25 A with
// the enable off. `head` holds the top-level keys: interface = "...", and any others.
inline std::string frame_map(const std::string& head, double encoder_max_age_s) {
  return head + R"(
[[frames]]
id = 0x181
direction = "input"
length = 4
max_age_s = )" + std::to_string(encoder_max_age_s) + R"(
[[frames.channels]]
name = "encoder"
kind = "encoder_input"
byte_offset = 0
bytes = 4
signed = true
scale = 1e-6
unit = "m"
[[frames]]
id = 0x18FF0001
extended = true
direction = "input"
length = 2
[[frames.channels]]
name = "temperature"
kind = "analog_input"
byte_offset = 0
bytes = 2
byte_order = "big_endian"
scale = 0.1
[[frames]]
id = 0x201
direction = "output"
length = 3
period_s = 0.01
[[frames.channels]]
name = "current_cmd"
kind = "analog_output"
byte_offset = 0
bytes = 2
byte_order = "big_endian"
signed = true
scale = 0.001
unit = "A"
safe_value = -0.25
[[frames.channels]]
name = "enable"
kind = "digital_output"
byte_offset = 2
)";
}

}  // namespace hsa::io::socketcan_test
