// How a number lives in Modbus registers: 16-bit signed or unsigned, or 32 bits (integer or IEEE
// float) spread over two consecutive registers in either word order.
//
// Modbus itself only defines 16-bit big-endian registers; how a device packs wider values is its
// own choice, so the word order is a setting. Bytes inside a register are always big-endian on
// the wire, and libmodbus already hands us host-order uint16 registers, so only the order of
// the two words is left to configure.
//
// Pure functions on plain arrays: the bus thread calls them per poll, tests call them directly.
#pragma once

#include <cstdint>
#include <span>

namespace hsa::io::modbus {

enum class ValueType : unsigned char { int16, uint16, int32, float32 };
enum class WordOrder : unsigned char {
  high_first,  // "ABCD": the most significant word at the lower address (Modbus's own convention)
  low_first,   // "CDAB": the least significant word first, common on PLCs
};

constexpr int register_count(ValueType type) {
  return type == ValueType::int32 || type == ValueType::float32 ? 2 : 1;
}

// The number stored in `regs` (register_count(type) of them), before scale and offset.
double decode(ValueType type, WordOrder order, std::span<const std::uint16_t> regs);

// Stores `raw` into `regs`. Integers are rounded to nearest and saturated at the type's range,
// because wrapping a too-large valve command round to the opposite sign would be the worst
// possible failure. `raw` must not be NaN (the caller substitutes the safe value).
void encode(ValueType type, WordOrder order, double raw, std::span<std::uint16_t> regs);

}  // namespace hsa::io::modbus
