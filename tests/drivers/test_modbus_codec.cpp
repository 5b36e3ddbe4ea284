// The modbus plugin's pure parts: register encoding in every type and word order, and the
// triple buffer that carries values between the bus thread and the RT thread.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

#include "drivers/modbus/register_codec.hpp"
#include "drivers/modbus/triple_buffer.hpp"
#include "tests/support/yield_until.hpp"

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

TEST(TripleBuffer, ReaderGetsTheLatestPublishedValueOrKeepsItsOwn) {
  TripleBuffer<int> buffer(0);
  EXPECT_FALSE(buffer.fetch());
  EXPECT_EQ(buffer.front(), 0);
  buffer.back() = 1;
  buffer.publish();
  buffer.back() = 2;
  buffer.publish();  // 1 was never fetched: overwritten
  EXPECT_TRUE(buffer.fetch());
  EXPECT_EQ(buffer.front(), 2);
  EXPECT_FALSE(buffer.fetch());  // nothing new: the reader keeps 2
  EXPECT_EQ(buffer.front(), 2);
  buffer.back() = 3;
  buffer.publish();
  EXPECT_TRUE(buffer.fetch());
  EXPECT_EQ(buffer.front(), 3);
}

// A writer thread publishes arrays whose elements all equal a counter; the reader must never see
// a mix (a torn array) and never see the counter go backwards. Every 1000 publishes the writer
// waits (bounded) until the reader has fetched that very value: on a loaded machine, or pinned to
// one CPU, the writer could otherwise finish before the reader ever ran, and nothing would overlap.
TEST(TripleBuffer, ConcurrentReaderNeverSeesATornOrOlderArray) {
  constexpr std::size_t width = 64;
  constexpr long kPublishes = 200000;
  constexpr long kCheckpoint = 1000;
  TripleBuffer<std::vector<long>> buffer(std::vector<long>(width, 0));
  std::atomic<bool> done{false};
  std::atomic<long> reader_saw{0};
  std::atomic<int> checkpoints_missed{0};
  std::thread writer([&] {
    for (long n = 1; n <= kPublishes; ++n) {
      auto& b = buffer.back();
      for (auto& x : b) x = n;
      buffer.publish();
      if (n % kCheckpoint == 0 && !hsa::test::yield_until([&] { return reader_saw.load() >= n; })) {
        ++checkpoints_missed;
      }
    }
    done = true;
  });
  long last = 0;
  long fetches = 0;
  long torn = 0;
  long backwards = 0;
  while (!done.load()) {
    if (!buffer.fetch()) {
      std::this_thread::yield();
      continue;
    }
    ++fetches;
    const auto& f = buffer.front();
    for (const long x : f) torn += x != f[0];
    backwards += f[0] < last;
    last = f[0];
    reader_saw.store(last);
  }
  writer.join();
  buffer.fetch();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(buffer.front()[0], kPublishes);  // the very last value is never lost
  EXPECT_EQ(checkpoints_missed.load(), 0);
  // Each checkpoint needed a fetch made while the writer was running.
  EXPECT_GE(fetches, kPublishes / kCheckpoint);
}

}  // namespace
}  // namespace hsa::io::modbus
