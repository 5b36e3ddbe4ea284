// SpscRing: capacity rules, FIFO order, full/empty behaviour, wrap-around, and a two-thread run
// that checks order and no loss.
#include "lockfree/spsc_ring.hpp"
#include "tests/support/yield_until.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <thread>

namespace hsa::lockfree {
namespace {

TEST(SpscRing, RefusesCapacityThatIsNotAPowerOfTwo) {
  EXPECT_THROW(SpscRing<int>(0), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(3), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(1000), std::invalid_argument);
  EXPECT_NO_THROW(SpscRing<int>(1));
  EXPECT_EQ(SpscRing<int>(1024).capacity(), 1024u);
}

TEST(SpscRing, IndicesLiveOnSeparateCacheLines) {
  EXPECT_EQ(alignof(SpscRing<int>), kCacheLineSize);
  EXPECT_GE(sizeof(SpscRing<int>), 3 * kCacheLineSize);
}

TEST(SpscRing, PopsInPushOrderAndReportsEmpty) {
  SpscRing<int> ring(4);
  int out = -1;
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_EQ(out, -1);  // untouched when empty
  ASSERT_TRUE(ring.try_push(1));
  ASSERT_TRUE(ring.try_push(2));
  ASSERT_TRUE(ring.try_push(3));
  EXPECT_EQ(ring.size(), 3u);
  for (int expected : {1, 2, 3}) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, expected);
  }
  EXPECT_FALSE(ring.try_pop(out));
  EXPECT_TRUE(ring.empty());
}

TEST(SpscRing, FullRingRefusesAndKeepsItsContents) {
  SpscRing<int> ring(4);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99));  // every slot is usable, and no more
  EXPECT_EQ(ring.size(), 4u);
  int out = -1;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(ring.try_push(4));  // one slot freed, one accepted
  EXPECT_FALSE(ring.try_push(5));
  for (int expected = 1; expected <= 4; ++expected) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, expected);
  }
  EXPECT_FALSE(ring.try_pop(out));
}

TEST(SpscRing, WrapsAroundManyTimes) {
  SpscRing<std::uint64_t> ring(8);
  std::uint64_t next_in = 0;
  std::uint64_t next_out = 0;
  // Uneven push/pop batches walk the indices across the wrap in every phase.
  for (int round = 0; round < 1000; ++round) {
    const int pushes = 1 + round % 7;
    for (int i = 0; i < pushes; ++i) ASSERT_TRUE(ring.try_push(next_in++));
    std::uint64_t out = 0;
    while (ring.try_pop(out)) ASSERT_EQ(out, next_out++);
  }
  EXPECT_EQ(next_out, next_in);
}

struct Record {
  std::uint64_t seq;
  double payload[5];  // bigger than a word, so a torn copy would show
};

TEST(SpscRing, TwoThreadsKeepOrderAndLoseNothing) {
  constexpr std::uint64_t kCount = 2'000'000;
  SpscRing<Record> ring(256);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);

  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount; ++i) {
      Record r{i, {}};
      for (double& p : r.payload) p = static_cast<double>(i);
      // The producer retries when full, so nothing is dropped: the consumer must see all of it.
      while (!ring.try_push(r)) {
        if (std::chrono::steady_clock::now() > deadline) return;
        std::this_thread::yield();
      }
    }
  });

  std::uint64_t expected = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t torn = 0;
  Record r{};
  while (expected < kCount && std::chrono::steady_clock::now() < deadline) {
    if (!ring.try_pop(r)) {
      std::this_thread::yield();
      continue;
    }
    if (r.seq != expected) ++out_of_order;
    for (const double p : r.payload) {
      if (p != static_cast<double>(r.seq)) ++torn;
    }
    expected = r.seq + 1;
  }
  producer.join();

  EXPECT_EQ(expected, kCount) << "consumer stopped early (deadline)";
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_FALSE(ring.try_pop(r));
}

TEST(SpscRing, TwoThreadsWithDropsDeliverAnIncreasingSubsequence) {
  // The RT pattern: the producer never waits on a full ring; it drops and counts. Only as a test
  // device, every 10,000 pushes it waits (bounded) until the consumer has popped something since
  // the last checkpoint: on a loaded machine, or pinned to one CPU, the producer could otherwise
  // finish before the consumer ever ran, and nothing would overlap.
  constexpr std::uint64_t kCount = 500'000;
  constexpr std::uint64_t kCheckpoint = 10'000;
  SpscRing<std::uint64_t> ring(64);
  std::uint64_t drops = 0;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> popped{0};
  std::atomic<int> checkpoints_missed{0};
  std::thread producer([&] {
    std::uint64_t popped_at_checkpoint = 0;
    for (std::uint64_t i = 0; i < kCount; ++i) {
      if (!ring.try_push(i)) ++drops;
      if ((i + 1) % kCheckpoint == 0) {
        if (!hsa::test::yield_until([&] { return popped.load() > popped_at_checkpoint; })) ++checkpoints_missed;
        popped_at_checkpoint = popped.load();
      }
    }
    done.store(true, std::memory_order_release);
  });

  std::uint64_t received = 0;
  std::uint64_t last = 0;
  bool first = true;
  bool increasing = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::uint64_t v = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (ring.try_pop(v)) {
      if (!first && v <= last) increasing = false;
      first = false;
      last = v;
      ++received;
      popped.store(received);
    } else if (done.load(std::memory_order_acquire) && ring.empty()) {
      break;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();

  EXPECT_TRUE(increasing);
  EXPECT_EQ(received + drops, kCount);  // every value either arrived or was counted as dropped
  EXPECT_EQ(checkpoints_missed.load(), 0);
  EXPECT_GE(received, kCount / kCheckpoint);  // pops made while the producer ran
}

}  // namespace
}  // namespace hsa::lockfree
