// The CAN frame codec (drivers/socketcan/can_codec.hpp) on any field, payload and value.
// Input: offset, size, byte order, signedness, 8 bytes of a double to pack, then the 8-byte payload.
// Invariants: unpacking any payload gives an integer within the field's range; packing a number
// touches only the field's bytes and, for fields up to 6 bytes (exact in a double), unpacks to the
// number rounded and saturated at the field's range.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "drivers/socketcan/can_codec.hpp"
#include "tests/fuzz/fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hsa::io::socketcan;
  if (size < 4 + sizeof(double)) return 0;
  Field f;
  f.size = 1 + data[1] % 8;
  f.offset = data[0] % (9 - f.size);
  f.order = data[2] % 2 ? ByteOrder::big_endian : ByteOrder::little_endian;
  f.is_signed = data[3] % 2;
  double raw;
  std::memcpy(&raw, data + 4, sizeof raw);
  std::array<std::uint8_t, 8> payload{};
  std::memcpy(payload.data(), data + 4 + sizeof raw, std::min(payload.size(), size - 4 - sizeof raw));

  const double value = unpack(f, payload);
  HSA_FUZZ_CHECK(value == std::nearbyint(value) && value >= field_min(f) && value <= field_max(f));

  if (std::isnan(raw)) return 0;  // the caller substitutes the safe value for NaN
  const std::array<std::uint8_t, 8> before = payload;
  pack(f, raw, payload);
  for (int i = 0; i < 8; ++i) {
    if (i < f.offset || i >= f.offset + f.size) HSA_FUZZ_CHECK(payload[i] == before[i]);
  }
  const double back = unpack(f, payload);
  HSA_FUZZ_CHECK(back >= field_min(f) && back <= field_max(f));
  if (f.size <= 6) HSA_FUZZ_CHECK(back == std::clamp(std::nearbyint(raw), field_min(f), field_max(f)));
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  std::vector<std::string> seeds;
  for (const double raw : {0.0, 100.4, -100.6, 70000.0, -1e20}) {
    for (char size = 0; size < 8; ++size) {
      std::string s = {static_cast<char>(size * 3), size, static_cast<char>(size % 2), static_cast<char>(size / 2)};
      s.append(reinterpret_cast<const char*>(&raw), sizeof raw);
      s.append("\x01\x80\xff\x7f\x00\x10\x20\x30", 8);
      seeds.push_back(s);
    }
  }
  return seeds;
}
