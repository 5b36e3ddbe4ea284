// The Modbus register codec (drivers/modbus/register_codec.hpp) on any registers and any value.
// Input: type, word order, 8 bytes of a double to encode, then the registers to decode.
// Invariants: decoding any registers gives the type's value (an integer in the type's range, or any
// float); encoding a number and decoding it gives the number rounded and saturated at the type's
// range (integers) or the nearest float, saturated at float's largest (float32).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "drivers/modbus/register_codec.hpp"
#include "tests/fuzz/fuzz_target.hpp"

namespace {

using namespace hsa::io::modbus;

double type_min(ValueType t) {
  switch (t) {
    case ValueType::int16: return -32768.0;
    case ValueType::uint16: return 0.0;
    case ValueType::int32: return -2147483648.0;
    case ValueType::float32: return -std::numeric_limits<float>::max();
  }
  return 0.0;
}

double type_max(ValueType t) {
  switch (t) {
    case ValueType::int16: return 32767.0;
    case ValueType::uint16: return 65535.0;
    case ValueType::int32: return 2147483647.0;
    case ValueType::float32: return std::numeric_limits<float>::max();
  }
  return 0.0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2 + sizeof(double)) return 0;
  const auto type = static_cast<ValueType>(data[0] % 4);
  const auto order = static_cast<WordOrder>(data[1] % 2);
  double raw;
  std::memcpy(&raw, data + 2, sizeof raw);
  const std::size_t n = static_cast<std::size_t>(register_count(type));

  std::uint16_t regs[2] = {0, 0};
  std::memcpy(regs, data + 2 + sizeof raw, std::min(sizeof regs, size - 2 - sizeof raw));
  const double decoded = decode(type, order, std::span<const std::uint16_t>(regs, n));
  if (type != ValueType::float32) {
    HSA_FUZZ_CHECK(decoded == std::nearbyint(decoded) && decoded >= type_min(type) && decoded <= type_max(type));
  }

  if (std::isnan(raw)) return 0;  // the caller substitutes the safe value for NaN
  std::uint16_t out[2] = {0, 0};
  encode(type, order, raw, std::span<std::uint16_t>(out, n));
  const double back = decode(type, order, std::span<const std::uint16_t>(out, n));
  const double clamped = std::clamp(raw, type_min(type), type_max(type));
  if (type == ValueType::float32) {
    HSA_FUZZ_CHECK(back == static_cast<double>(static_cast<float>(clamped)));
  } else {
    HSA_FUZZ_CHECK(back == std::clamp(std::nearbyint(raw), type_min(type), type_max(type)));
  }
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  std::vector<std::string> seeds;
  for (const double raw : {0.0, 1.5, -1.5, 40000.0, -3e9, 1e300}) {
    for (char type = 0; type < 4; ++type) {
      std::string s = {type, static_cast<char>(type % 2)};
      s.append(reinterpret_cast<const char*>(&raw), sizeof raw);
      s.append("\x12\x34\xfe\xdc", 4);
      seeds.push_back(s);
    }
  }
  return seeds;
}
