// The modbus plugin's pure part: register encoding in every type and word order.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "drivers/modbus/register_codec.hpp"

namespace hsa::io::modbus {
namespace {

using Regs = std::array<std::uint16_t, 2>;

Regs encoded(ValueType type, WordOrder order, double raw) {
  Regs r{0xAAAA, 0xAAAA};
  encode(type, order, raw, r);
  return r;
}

TEST(ModbusCodec, KnownBitPatternsInBothWordOrders) {
  // -100000 = 0xFFFE7960, 12.5f = 0x41480000: the values the pymodbus peer serves.
  EXPECT_EQ(encoded(ValueType::int32, WordOrder::high_first, -100000), (Regs{0xFFFE, 0x7960}));
  EXPECT_EQ(encoded(ValueType::int32, WordOrder::low_first, -100000), (Regs{0x7960, 0xFFFE}));
  EXPECT_EQ(encoded(ValueType::float32, WordOrder::high_first, 12.5), (Regs{0x4148, 0x0000}));
  EXPECT_EQ(encoded(ValueType::float32, WordOrder::low_first, 12.5), (Regs{0x0000, 0x4148}));
  EXPECT_EQ(encoded(ValueType::int16, WordOrder::high_first, -1234)[0], 0xFB2E);
  EXPECT_EQ(encoded(ValueType::int16, WordOrder::high_first, -1234)[1], 0xAAAA);  // one register only

  EXPECT_EQ(decode(ValueType::int32, WordOrder::high_first, Regs{0xFFFE, 0x7960}), -100000);
  EXPECT_EQ(decode(ValueType::int32, WordOrder::low_first, Regs{0x7960, 0xFFFE}), -100000);
  EXPECT_EQ(decode(ValueType::float32, WordOrder::low_first, Regs{0x0000, 0x4148}), 12.5);
  EXPECT_EQ(decode(ValueType::int16, WordOrder::high_first, Regs{0xFB2E, 0}), -1234);
  EXPECT_EQ(decode(ValueType::uint16, WordOrder::high_first, Regs{0xFB2E, 0}), 0xFB2E);
}

TEST(ModbusCodec, RoundTripsEveryType) {
  for (const WordOrder order : {WordOrder::high_first, WordOrder::low_first}) {
    for (const double v : {-32768.0, -1.0, 0.0, 1.0, 32767.0}) {
      EXPECT_EQ(decode(ValueType::int16, order, encoded(ValueType::int16, order, v)), v);
    }
    for (const double v : {0.0, 1.0, 65535.0}) {
      EXPECT_EQ(decode(ValueType::uint16, order, encoded(ValueType::uint16, order, v)), v);
    }
    for (const double v : {-2147483648.0, -70000.0, 70000.0, 2147483647.0}) {
      EXPECT_EQ(decode(ValueType::int32, order, encoded(ValueType::int32, order, v)), v);
    }
    for (const double v : {-3.25e6, 1.0e-3, 2.5e7}) {
      EXPECT_EQ(decode(ValueType::float32, order, encoded(ValueType::float32, order, v)),
                static_cast<float>(v));
    }
  }
}

TEST(ModbusCodec, IntegersRoundAndSaturateInsteadOfWrapping) {
  const auto i16 = [](double raw) {
    return decode(ValueType::int16, WordOrder::high_first, encoded(ValueType::int16, WordOrder::high_first, raw));
  };
  EXPECT_EQ(i16(2.6), 3);
  EXPECT_EQ(i16(-2.6), -3);
  EXPECT_EQ(i16(40000), 32767);  // wrapping would give a large negative command
  EXPECT_EQ(i16(-1e9), -32768);
  const auto u16 = [](double raw) {
    return decode(ValueType::uint16, WordOrder::high_first, encoded(ValueType::uint16, WordOrder::high_first, raw));
  };
  EXPECT_EQ(u16(-5), 0);
  EXPECT_EQ(u16(70000), 65535);
  const auto i32 = [](double raw) {
    return decode(ValueType::int32, WordOrder::low_first, encoded(ValueType::int32, WordOrder::low_first, raw));
  };
  EXPECT_EQ(i32(1e12), 2147483647.0);
  const double big = decode(ValueType::float32, WordOrder::high_first,
                            encoded(ValueType::float32, WordOrder::high_first, 1e300));
  EXPECT_EQ(big, std::numeric_limits<float>::max());
}

}  // namespace
}  // namespace hsa::io::modbus
