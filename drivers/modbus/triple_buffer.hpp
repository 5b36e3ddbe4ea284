// A wait-free single-producer single-consumer exchange of "the latest value": the writer never
// blocks the reader and the reader never blocks the writer, and neither ever sees a half-written
// value.
//
// Why a triple buffer and not a seqlock: a seqlock reader retries while the writer is inside its
// write, and the Modbus I/O thread can be preempted there for any length of time; the RT thread
// must not spin on that. Here each side owns one of three buffers outright and they swap the
// third ("middle") with a single atomic exchange, so both sides finish in a bounded number of
// steps whatever the other one does. Intermediate values the reader never picked up are simply
// overwritten, which is what "latest value" means.
//
// The three buffers are built once (by the constructor, off the RT path), so T may own heap
// storage (a std::vector sized at configure): publishing and fetching only swap indices.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace hsa::io::modbus {

template <typename T>
class TripleBuffer {
 public:
  explicit TripleBuffer(const T& initial) : buffers_{initial, initial, initial} {}
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // Writer side: fill back(), then publish() it.
  T& back() { return buffers_[back_]; }
  void publish() noexcept {
    // Release: the reader that acquires this index sees everything written into the buffer.
    const std::uint8_t previous = middle_.exchange(back_ | fresh_bit, std::memory_order_acq_rel);
    back_ = previous & index_mask;
  }

  // Reader side: fetch() takes the newest published buffer if there is one (returns false and
  // keeps the current one otherwise); front() is the buffer the reader holds.
  bool fetch() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & fresh_bit) == 0) return false;
    const std::uint8_t previous = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = previous & index_mask;
    return true;
  }
  [[nodiscard]] const T& front() const { return buffers_[front_]; }

 private:
  static constexpr std::uint8_t fresh_bit = 0x4;
  static constexpr std::uint8_t index_mask = 0x3;

  std::array<T, 3> buffers_;
  std::uint8_t back_ = 0;                // owned by the writer
  std::uint8_t front_ = 1;               // owned by the reader
  std::atomic<std::uint8_t> middle_{2};  // index of the spare buffer, plus fresh_bit if unread
  static_assert(std::atomic<std::uint8_t>::is_always_lock_free, "the RT side must never take a lock");
};

}  // namespace hsa::io::modbus
