// A wait-free handoff of "the latest value" from one writer thread to one reader thread.
//
// Three slots: the writer owns one ("back"), the reader owns one ("front"), and the third
// ("middle") is exchanged through one atomic byte that also carries a "fresh" flag. The writer
// fills its back slot and publishes it by swapping it into the middle; the reader swaps the middle
// out when it is fresh. Each side finishes in a bounded number of steps whatever the other does,
// copies happen outside the atomic, and nothing allocates: the reader sees either nothing new or
// the latest complete value, never a torn one. Intermediate values the reader did not take are
// overwritten, which is what "latest value" means.
//
// Why not a seqlock: its reader retries while the writer is inside its write, and a writer on a
// normal thread (the Modbus bus thread, the operator thread) can be preempted there for any length
// of time; the RT thread must not spin on that.
//
// The slots are built once, by the constructor (off the RT path), so T may own heap storage (a
// std::vector sized at configure): back()/publish() and fetch()/front() only swap indices. Used
// between the Modbus bus thread and the RT thread, and between the operator and RT threads.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace hsa::lockfree {

template <typename T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // Writer: fill back() in place, then publish() it; or publish(value), which copies.
  T& back() noexcept { return slots_[back_]; }
  void publish() noexcept {
    // Release: the reader that acquires this index sees everything written into the slot.
    back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel) & kIndex;
  }
  void publish(const T& value) noexcept(std::is_nothrow_copy_assignable_v<T>) {
    back() = value;
    publish();
  }

  // Reader: fetch() takes the newest published slot if there is one (false, and the reader keeps
  // its slot, otherwise); front() is the slot the reader holds. take() is both in one: the latest
  // value if one arrived since the last take, else nullptr; valid until the next fetch or take.
  bool fetch() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return true;
  }
  [[nodiscard]] const T& front() const noexcept { return slots_[front_]; }
  const T* take() noexcept { return fetch() ? &front() : nullptr; }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;

  std::array<T, 3> slots_{};
  std::uint8_t back_ = 0;                // the writer's
  std::uint8_t front_ = 1;               // the reader's
  std::atomic<std::uint8_t> middle_{2};  // the spare slot's index, plus kFresh if unread
  static_assert(std::atomic<std::uint8_t>::is_always_lock_free, "the RT side must never take a lock");
};

}  // namespace hsa::lockfree
