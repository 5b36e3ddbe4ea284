// The socketcan plugin's settings, parsed and checked in on_configure into plain structs the RT
// path uses without touching TOML again.
//
//   interface = "can0"           required: the CAN network interface (can0, vcan0, ...)
//   max_frames_per_read = 64     bound on the frames one read() drains from the socket
//   max_age_s = 0.1              default staleness limit of input frames
//   output_timeout_s = 0.005     when write() has not run for this long (a stalled daemon), the
//                                plugin's watchdog thread sends the safe frames
//   byte_order = "little_endian" default for channels: "little_endian" or "big_endian"
//
//   [[frames]]
//   id = 0x181                   required: 11-bit (0..0x7FF), or 29-bit with extended = true
//   extended = false
//   fd = false                   a CAN FD frame (the interface's MTU must be 72)
//   direction = "input"          required: "input" (received) or "output" (sent)
//   length = 4                   required: payload bytes, 1..8 (FD: up to 64, a valid FD length);
//                                a received frame of another length is rejected and counted
//   max_age_s = 0.02             inputs: no valid frame for longer than this marks its channels
//                                stale (set it to a few of the sender's periods)
//   period_s = 0.01              outputs: send at most this often (default: every write())
//
//   [[frames.channels]]
//   name = "encoder"   kind = "encoder_input"   byte_offset = 0   bytes = 4
//   byte_order = "big_endian"   signed = true   scale = 1e-6   offset = 0.0   unit = "m"
//   safe_value = 0.0             outputs (true/false for digital): sent on deactivate
//
// Input frames carry encoder_input, analog_input and digital_input channels; output frames
// analog_output and digital_output. Analog channels need `bytes` (1..8) and take byte_order,
// signed, scale, offset and unit: value = raw * scale + offset, raw = (value - offset) / scale.
// Digital channels take `bytes` (default 1) and read 1 when any bit is set, write 0 or 1. A
// channel lies inside its frame's length and does not overlap another channel of the frame. Bytes
// of an output frame that no channel covers are sent as 0.
//
// Every setting error throws a ConfigError (drivers/table_reader.hpp) naming the place and the key:
//   hsad.toml:40:9: frames[0].channels[1].bytes: expected at most 2 to fit in the frame's 4 bytes
//   from byte_offset 2, got 4
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/socketcan/can_codec.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io::socketcan {

enum class Direction : unsigned char { input, output };

struct ChannelMap {
  ChannelInfo info;
  ChannelCodec codec;
  double safe_value = 0.0;  // outputs: sent on deactivate, and in place of a NaN command
};

struct FrameMap {
  std::uint32_t id = 0;  // without flags
  bool extended = false;
  bool fd = false;
  Direction direction = Direction::input;
  int length = 0;        // payload bytes
  Duration max_age{};    // inputs
  Duration period{};     // outputs; zero: every write()
  std::vector<ChannelMap> channels;

  // The id as the kernel's can_id carries it: with CAN_EFF_FLAG when extended.
  [[nodiscard]] std::uint32_t can_id() const;
  // "frame 0x181" or "frame 0x18FF0001 (extended)", for messages.
  [[nodiscard]] std::string describe() const;
};

struct CanSettings {
  std::string interface;
  int max_frames_per_read = 64;
  Duration output_timeout = std::chrono::milliseconds(5);
  std::vector<FrameMap> frames;

  [[nodiscard]] bool uses_fd() const;
};

// The names of the status channels the driver always declares after the configured ones.
inline constexpr const char* length_errors_channel = "length_errors";
inline constexpr const char* error_frames_channel = "error_frames";
inline constexpr const char* tx_dropped_channel = "tx_dropped";
inline constexpr const char* bus_off_channel = "bus_off";
inline constexpr const char* output_timeouts_channel = "output_timeouts";

// Throws ConfigError.
CanSettings parse_can_settings(const toml::table& table);

}  // namespace hsa::io::socketcan
