// TripleBuffer: the latest value, whole and in order, from one thread to another.
#include "lockfree/triple_buffer.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "tests/support/yield_until.hpp"

namespace hsa::lockfree {
namespace {

TEST(TripleBuffer, TakeGivesEachPublishedValueOnce) {
  TripleBuffer<int> buffer;
  EXPECT_EQ(buffer.take(), nullptr);
  buffer.publish(7);
  const int* taken = buffer.take();
  ASSERT_NE(taken, nullptr);
  EXPECT_EQ(*taken, 7);
  EXPECT_EQ(buffer.take(), nullptr);  // nothing new since
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
}  // namespace hsa::lockfree
