#include "drivers/modbus/register_codec.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace hsa::io::modbus {
namespace {

std::uint32_t join(WordOrder order, std::span<const std::uint16_t> regs) {
  const std::uint32_t first = regs[0];
  const std::uint32_t second = regs[1];
  return order == WordOrder::high_first ? (first << 16) | second : (second << 16) | first;
}

void split(WordOrder order, std::uint32_t value, std::span<std::uint16_t> regs) {
  const auto high = static_cast<std::uint16_t>(value >> 16);
  const auto low = static_cast<std::uint16_t>(value & 0xFFFFu);
  regs[0] = order == WordOrder::high_first ? high : low;
  regs[1] = order == WordOrder::high_first ? low : high;
}

template <typename Int>
Int saturate(double raw) {
  const double r = std::nearbyint(raw);
  if (r <= static_cast<double>(std::numeric_limits<Int>::min())) return std::numeric_limits<Int>::min();
  if (r >= static_cast<double>(std::numeric_limits<Int>::max())) return std::numeric_limits<Int>::max();
  return static_cast<Int>(r);
}

}  // namespace

double decode(ValueType type, WordOrder order, std::span<const std::uint16_t> regs) {
  switch (type) {
    case ValueType::int16: return static_cast<std::int16_t>(regs[0]);
    case ValueType::uint16: return regs[0];
    case ValueType::int32: return static_cast<std::int32_t>(join(order, regs));
    case ValueType::float32: return std::bit_cast<float>(join(order, regs));
  }
  return 0.0;
}

void encode(ValueType type, WordOrder order, double raw, std::span<std::uint16_t> regs) {
  switch (type) {
    case ValueType::int16:
      regs[0] = static_cast<std::uint16_t>(saturate<std::int16_t>(raw));
      return;
    case ValueType::uint16:
      regs[0] = saturate<std::uint16_t>(raw);
      return;
    case ValueType::int32:
      split(order, static_cast<std::uint32_t>(saturate<std::int32_t>(raw)), regs);
      return;
    case ValueType::float32: {
      // Beyond float's range the cast is undefined behaviour: saturate to the largest finite.
      constexpr double max = std::numeric_limits<float>::max();
      split(order, std::bit_cast<std::uint32_t>(static_cast<float>(std::clamp(raw, -max, max))), regs);
      return;
    }
  }
}

}  // namespace hsa::io::modbus
