// How a number lives in a CAN frame's payload: an integer of 1 to 8 whole bytes at a byte
// offset, little- or big-endian, signed (two's complement) or unsigned, and the scale and offset
// that turn it into the channel's unit.
//
//   decode: value = raw * scale + offset           (digital: 1 when raw != 0, else 0)
//   encode: raw = round((value - offset) / scale), saturated at the field's range
//                                                   (digital: 1 when value != 0, else 0)
//
// Saturation rather than wrapping, because a too-large valve command wrapped round to the
// opposite sign would be the worst possible failure. Little-endian is the default elsewhere
// because CANopen and J1939 put their numbers that way; many encoders send big-endian ("Motorola").
//
// Values travel as doubles (the framework's slot type), so a field wider than 53 bits carries
// exact integers only up to 2^53; any encoder or current fits long before that.
//
// Pure functions on plain byte spans: the RT path calls them per frame, tests call them directly.
// Nothing here allocates.
#pragma once

#include <cstdint>
#include <span>

namespace hsa::io::socketcan {

enum class ByteOrder : unsigned char {
  little_endian,  // least significant byte at the lowest offset ("Intel")
  big_endian,     // most significant byte at the lowest offset ("Motorola")
};

// Where an integer lives in a payload.
struct Field {
  int offset = 0;  // first byte, 0-based
  int size = 1;    // bytes, 1..8
  ByteOrder order = ByteOrder::little_endian;
  bool is_signed = false;
};

// The smallest and largest raw integer the field holds, as doubles (a 64-bit range rounds to the
// nearest double).
double field_min(const Field& field);
double field_max(const Field& field);

// The integer stored in `payload` (which must hold offset + size bytes).
double unpack(const Field& field, std::span<const std::uint8_t> payload);

// Stores round(raw) into `payload`, saturated at [field_min, field_max]; the other bytes are left
// as they are. `raw` must not be NaN: the caller substitutes the safe value.
void pack(const Field& field, double raw, std::span<std::uint8_t> payload);

// A channel's field with its conversion to and from the channel's unit.
struct ChannelCodec {
  Field field;
  double scale = 1.0;  // unit per count; finite, non-zero
  double offset = 0.0;
  bool digital = false;  // 0/1 channel: scale and offset unused

  [[nodiscard]] double decode(std::span<const std::uint8_t> payload) const;
  // `value` must not be NaN.
  void encode(double value, std::span<std::uint8_t> payload) const;
};

}  // namespace hsa::io::socketcan
