#include "drivers/socketcan/can_codec.hpp"

#include <cmath>
#include <limits>

namespace hsa::io::socketcan {
namespace {

// The field's range as integers: [-2^(n-1), 2^(n-1) - 1] or [0, 2^n - 1] for n = 8 * size bits.
std::int64_t signed_min(int size) {
  return size == 8 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (8 * size - 1));
}
std::int64_t signed_max(int size) {
  return size == 8 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << (8 * size - 1)) - 1;
}
std::uint64_t unsigned_max(int size) {
  return size == 8 ? std::numeric_limits<std::uint64_t>::max() : (std::uint64_t{1} << (8 * size)) - 1;
}

// Payload index of the field's i-th byte counted from the least significant one.
int byte_index(const Field& f, int i) {
  return f.order == ByteOrder::little_endian ? f.offset + i : f.offset + f.size - 1 - i;
}

}  // namespace

double field_min(const Field& f) {
  return f.is_signed ? static_cast<double>(signed_min(f.size)) : 0.0;
}

double field_max(const Field& f) {
  return f.is_signed ? static_cast<double>(signed_max(f.size)) : static_cast<double>(unsigned_max(f.size));
}

double unpack(const Field& f, std::span<const std::uint8_t> payload) {
  std::uint64_t u = 0;
  for (int i = f.size - 1; i >= 0; --i) u = (u << 8) | payload[byte_index(f, i)];
  if (!f.is_signed) return static_cast<double>(u);
  if (f.size < 8 && (u >> (8 * f.size - 1)) != 0) u |= ~unsigned_max(f.size);  // sign-extend
  return static_cast<double>(static_cast<std::int64_t>(u));
}

void pack(const Field& f, double raw, std::span<std::uint8_t> payload) {
  const double r = std::nearbyint(raw);
  std::uint64_t u = 0;
  // Compare in double, convert only inside the range: out-of-range conversion is undefined. The
  // upper bounds of 64-bit fields round up to 2^63 and 2^64 as doubles, hence >= there.
  if (f.is_signed) {
    const std::int64_t low = signed_min(f.size);
    const std::int64_t high = signed_max(f.size);
    const std::int64_t v = r <= static_cast<double>(low)    ? low
                           : r >= static_cast<double>(high) ? high
                                                            : static_cast<std::int64_t>(r);
    u = static_cast<std::uint64_t>(v);
  } else {
    const std::uint64_t high = unsigned_max(f.size);
    u = r <= 0.0 ? 0 : r >= static_cast<double>(high) ? high : static_cast<std::uint64_t>(r);
  }
  for (int i = 0; i < f.size; ++i) {
    payload[byte_index(f, i)] = static_cast<std::uint8_t>(u & 0xFFu);
    u >>= 8;
  }
}

double ChannelCodec::decode(std::span<const std::uint8_t> payload) const {
  const double raw = unpack(field, payload);
  if (digital) return raw != 0.0 ? 1.0 : 0.0;
  return raw * scale + offset;
}

void ChannelCodec::encode(double value, std::span<std::uint8_t> payload) const {
  if (digital) {
    pack(field, value != 0.0 ? 1.0 : 0.0, payload);
    return;
  }
  pack(field, (value - offset) / scale, payload);
}

}  // namespace hsa::io::socketcan
