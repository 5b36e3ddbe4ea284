// A bounded, lock-free single-producer single-consumer ring of trivially copyable values.
//
// It is how the LCM thread and the RT thread talk without locks: one thread only pushes, one
// thread only pops. The storage is allocated once, at construction (on a normal thread, before the
// RT thread runs); try_push and try_pop never allocate, never block and never make a system call.
// A full ring refuses the value (try_push returns false) and the caller counts the drop: the RT
// thread must not wait for a slow reader.
//
// Design: the capacity is a power of two so that an index maps to a slot by masking; head and tail
// are free-running 64-bit counters (they never wrap in practice), so full is tail - head ==
// capacity and no slot is wasted. The producer owns tail and the consumer owns head; each publishes
// its counter with a release store after touching the slot, and the other side reads it with an
// acquire load, which orders the slot's bytes before the counter. Each side also keeps a cached
// copy of the other's counter and re-reads the shared one only when the cache says full/empty,
// so in the common case a push or pop touches no cache line the other thread writes. The two
// counters live on separate cache lines to avoid false sharing.
#pragma once

#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <type_traits>

namespace hsa::lockfree {

// 64 bytes on every x86-64 and most ARM64 parts. std::hardware_destructive_interference_size would
// say the same but g++ warns (-Winterference-size) when it appears in a header's ABI.
inline constexpr std::size_t kCacheLineSize = 64;

template <typename T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing holds trivially copyable values only");
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "the ring needs lock-free 64-bit atomics");

 public:
  // Throws std::invalid_argument unless capacity is a power of two (and at least 1).
  explicit SpscRing(std::size_t capacity)
      : capacity_(checked_capacity(capacity)), mask_(capacity - 1), slots_(new T[capacity]{}) {}

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer only. False when full: the value is not stored.
  bool try_push(const T& value) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - producer_cached_head_ == capacity_) {
      producer_cached_head_ = head_.load(std::memory_order_acquire);
      if (tail - producer_cached_head_ == capacity_) return false;
    }
    slots_[tail & mask_] = value;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  // Consumer only. False when empty: `out` is untouched.
  bool try_pop(T& out) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head == consumer_cached_tail_) {
      consumer_cached_tail_ = tail_.load(std::memory_order_acquire);
      if (head == consumer_cached_tail_) return false;
    }
    out = slots_[head & mask_];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

  // Approximate when the other thread is active; exact when both are quiet. For diagnostics.
  [[nodiscard]] std::size_t size() const noexcept {
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    return static_cast<std::size_t>(tail - head);
  }
  [[nodiscard]] bool empty() const noexcept { return size() == 0; }

 private:
  static std::size_t checked_capacity(std::size_t capacity) {
    if (capacity == 0 || !std::has_single_bit(capacity)) {
      throw std::invalid_argument("SpscRing: capacity must be a power of two");
    }
    return capacity;
  }

  // Read-only after construction: shared by both threads without contention.
  const std::size_t capacity_;
  const std::size_t mask_;
  const std::unique_ptr<T[]> slots_;

  // Consumer's line: its counter and its cache of the producer's.
  alignas(kCacheLineSize) std::atomic<std::uint64_t> head_{0};
  std::uint64_t consumer_cached_tail_ = 0;

  // Producer's line.
  alignas(kCacheLineSize) std::atomic<std::uint64_t> tail_{0};
  std::uint64_t producer_cached_head_ = 0;
  // alignas makes sizeof a multiple of the line, so whatever follows the ring in memory does not
  // share the producer's line either.
};

}  // namespace hsa::lockfree
