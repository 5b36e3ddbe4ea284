// The socketcan frame codec: byte order, sign, sizes 1..8, saturation at the field's range, and
// the scale/offset conversion. Expected bytes are written out by hand, not computed by the code
// under test.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>

#include "drivers/socketcan/can_codec.hpp"

namespace hsa::io::socketcan {
namespace {

using Bytes = std::array<std::uint8_t, 8>;
constexpr auto little = ByteOrder::little_endian;
constexpr auto big = ByteOrder::big_endian;

Bytes packed(const Field& f, double raw, std::uint8_t fill = 0xAA) {
  Bytes b;
  b.fill(fill);
  pack(f, raw, b);
  return b;
}

TEST(SocketCanCodec, ReadsLittleAndBigEndian) {
  const Bytes b{0x34, 0x12, 0x78, 0x56, 0, 0, 0, 0};
  EXPECT_EQ(unpack({0, 2, little, false}, b), 0x1234);
  EXPECT_EQ(unpack({0, 2, big, false}, b), 0x3412);
  EXPECT_EQ(unpack({0, 4, little, false}, b), 0x56781234);
  EXPECT_EQ(unpack({0, 4, big, false}, b), 0x34127856);
  EXPECT_EQ(unpack({1, 2, little, false}, b), 0x7812);  // at a byte offset
  EXPECT_EQ(unpack({2, 1, big, false}, b), 0x78);
}

TEST(SocketCanCodec, ReadsTwosComplementWhenSigned) {
  const Bytes ff{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  for (int size = 1; size <= 8; ++size) {
    EXPECT_EQ(unpack({0, size, little, true}, ff), -1.0) << size;
  }
  EXPECT_EQ(unpack({0, 1, little, false}, ff), 255.0);
  EXPECT_EQ(unpack({0, 2, little, false}, ff), 65535.0);
  const Bytes b{0x80, 0x00, 0x00, 0x7F, 0xC0, 0x1D, 0xFE, 0xFF};
  EXPECT_EQ(unpack({0, 3, big, true}, b), -8388608.0);   // 0x800000
  EXPECT_EQ(unpack({0, 3, little, true}, b), 128.0);     // 0x000080
  EXPECT_EQ(unpack({3, 1, big, true}, b), 127.0);
  EXPECT_EQ(unpack({4, 4, little, true}, b), -123456.0);  // 0xFFFE1DC0
  EXPECT_EQ(unpack({4, 4, little, false}, b), 4294843840.0);
  const Bytes min64{0x80, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(unpack({0, 8, big, true}, min64), -9223372036854775808.0);
}

TEST(SocketCanCodec, WritesOnlyTheFieldsBytes) {
  EXPECT_EQ(packed({2, 2, little, false}, 0x1234), (Bytes{0xAA, 0xAA, 0x34, 0x12, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({2, 2, big, false}, 0x1234), (Bytes{0xAA, 0xAA, 0x12, 0x34, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({4, 4, little, true}, -123456), (Bytes{0xAA, 0xAA, 0xAA, 0xAA, 0xC0, 0x1D, 0xFE, 0xFF}));
  EXPECT_EQ(packed({0, 3, big, true}, -2), (Bytes{0xFF, 0xFF, 0xFE, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
  // A double carries 53 bits: an 8-byte value is exact when its low bits are zero.
  EXPECT_EQ(packed({0, 8, big, false}, 0x0102030405060700),
            (Bytes{0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x00}));
}

TEST(SocketCanCodec, RoundsToNearest) {
  EXPECT_EQ(packed({0, 1, little, true}, 2.6)[0], 3);
  EXPECT_EQ(packed({0, 1, little, true}, -2.6)[0], 0xFD);  // -3
  EXPECT_EQ(packed({0, 1, little, false}, 9.4)[0], 9);
}

TEST(SocketCanCodec, SaturatesAtTheFieldsRangeInsteadOfWrapping) {
  EXPECT_EQ(packed({0, 2, little, true}, 40000), (Bytes{0xFF, 0x7F, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({0, 2, little, true}, -40000), (Bytes{0x00, 0x80, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({0, 2, big, false}, 70000), (Bytes{0xFF, 0xFF, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({0, 2, big, false}, -5), (Bytes{0x00, 0x00, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA}));
  EXPECT_EQ(packed({0, 1, big, true}, 1e300)[0], 0x7F);
  EXPECT_EQ(packed({0, 8, big, true}, 1e30), (Bytes{0x7F, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(packed({0, 8, big, true}, -1e30), (Bytes{0x80, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(packed({0, 8, big, false}, 1e30), (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(packed({0, 4, little, true}, -inf), (Bytes{0x00, 0x00, 0x00, 0x80, 0xAA, 0xAA, 0xAA, 0xAA}));
}

TEST(SocketCanCodec, RangeOfEachSize) {
  EXPECT_EQ(field_min({0, 1, little, true}), -128.0);
  EXPECT_EQ(field_max({0, 1, little, true}), 127.0);
  EXPECT_EQ(field_max({0, 1, little, false}), 255.0);
  EXPECT_EQ(field_min({0, 3, little, true}), -8388608.0);
  EXPECT_EQ(field_max({0, 3, little, false}), 16777215.0);
  EXPECT_EQ(field_min({0, 4, little, false}), 0.0);
  EXPECT_EQ(field_max({0, 4, little, true}), 2147483647.0);
  EXPECT_EQ(field_min({0, 8, little, true}), -9223372036854775808.0);
}

TEST(SocketCanCodec, RoundTripsTheExtremesOfEverySizeOrderAndSign) {
  for (int size = 1; size <= 8; ++size) {
    for (const ByteOrder order : {little, big}) {
      for (const bool is_signed : {false, true}) {
        const Field f{8 - size, size, order, is_signed};
        // Exactly representable values: the ends of the range (below 2^53 the max is exact) and
        // small numbers of both signs.
        for (const double raw : {field_min(f), -1.0, 0.0, 1.0, 100.0, size < 7 ? field_max(f) : 4096.0}) {
          if (raw < field_min(f)) continue;
          EXPECT_EQ(unpack(f, packed(f, raw)), raw) << "size " << size << (is_signed ? " signed " : " unsigned ")
                                                    << (order == big ? "big" : "little") << " raw " << raw;
        }
      }
    }
  }
}

TEST(SocketCanCodec, ScalesAndOffsetsBothWays) {
  const ChannelCodec encoder{{0, 4, little, true}, 1e-6, 0.0, false};
  const Bytes position{0xC0, 0x1D, 0xFE, 0xFF, 0, 0, 0, 0};  // -123456 counts of 1 µm
  EXPECT_DOUBLE_EQ(encoder.decode(position), -0.123456);

  const ChannelCodec current{{1, 2, big, false}, 0.001, 0.0, false};  // mA on the wire, A in the channel
  Bytes b{};
  current.encode(1.5, b);
  EXPECT_EQ(b, (Bytes{0x00, 0x05, 0xDC, 0, 0, 0, 0, 0}));  // 1500
  EXPECT_DOUBLE_EQ(current.decode(b), 1.5);

  const ChannelCodec pressure{{0, 2, little, false}, 1000.0, -1e5, false};  // 1 kPa per count, -1 bar zero
  pressure.encode(2.4e6, b);  // (2.4e6 + 1e5) / 1000 = 2500 = 0x09C4
  EXPECT_EQ(b[0], 0xC4);
  EXPECT_EQ(b[1], 0x09);
  EXPECT_DOUBLE_EQ(pressure.decode(b), 2.4e6);
  current.encode(-1.0, b);  // below the unsigned field: saturates at 0, never wraps
  EXPECT_EQ(b[1], 0);
  EXPECT_EQ(b[2], 0);
}

TEST(SocketCanCodec, DigitalChannelsAreZeroOrOne) {
  const ChannelCodec flag{{3, 1, little, false}, 1.0, 0.0, true};
  Bytes b{};
  b[3] = 0x04;
  EXPECT_EQ(flag.decode(b), 1.0);
  b[3] = 0;
  EXPECT_EQ(flag.decode(b), 0.0);
  flag.encode(1.0, b);
  EXPECT_EQ(b[3], 1);
  flag.encode(0.0, b);
  EXPECT_EQ(b[3], 0);
}

}  // namespace
}  // namespace hsa::io::socketcan
