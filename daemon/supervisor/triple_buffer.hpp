// A wait-free handoff of a value from one writer thread to one reader thread (a triple buffer).
//
// Three slots: the writer owns one ("back"), the reader owns one ("front"), and the third
// ("middle") is exchanged through one atomic byte that also carries a "fresh" flag. publish()
// fills the back slot and swaps it into the middle; take() swaps the middle out when it is fresh.
// Neither side ever waits for the other, copies happen outside the atomic, and nothing allocates:
// the reader (the RT thread) sees either nothing new or the latest complete value, never a torn
// one. Intermediate values the reader did not take are overwritten, which is what a parameter
// change wants.
//
// Exactly one writer thread and one reader thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace hsa::daemon {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}

  // Writer.
  void publish(const T& value) {
    slots_[back_] = value;
    back_ = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel) &
            kIndex;
  }

  // Reader: the latest published value if one arrived since the last take(), else nullptr.
  // The pointer stays valid until the next take().
  const T* take() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return nullptr;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return &slots_[front_];
  }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;

  std::array<T, 3> slots_{};
  std::atomic<std::uint8_t> middle_{1};
  std::uint8_t back_ = 0;   // writer's
  std::uint8_t front_ = 2;  // reader's
};

}  // namespace hsa::daemon
