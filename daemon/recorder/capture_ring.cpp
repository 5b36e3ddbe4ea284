#include "daemon/recorder/capture_ring.hpp"

#include <algorithm>
#include <stdexcept>

namespace hsa::daemon {

CaptureRing::CaptureRing(std::size_t rows, std::size_t post_rows) : capacity_(rows), post_rows_(post_rows) {
  if (rows < 2) throw std::invalid_argument("flight recorder: a ring of at least 2 rows");
  if (post_rows >= rows) throw std::invalid_argument("flight recorder: post-trigger rows must be fewer than the ring's");
  for (Buffer& b : buffers_) {
    // Value-initialised: every page is written now, before the RT thread starts (and mlockall
    // keeps them), so the RT thread's first pass through the ring takes no page fault.
    b.rows = std::make_unique<RecorderRow[]>(rows);
  }
}

void CaptureRing::trigger(const CaptureTrigger& why) noexcept {
  bump(triggers_);
  if (armed_) {
    ++merged_;  // inside the window being collected: the file counts it
    bump(merged_count_);
    return;
  }
  armed_ = true;
  trigger_ = written_;
  merged_ = 0;
  why_ = why;
  // Within the ring whatever the caller asked: the trigger row and its post rows must fit.
  post_ = why.post_rows == kRingDefaultRows ? post_rows_ : std::min<std::uint64_t>(why.post_rows, capacity_ - 1);
  pre_ = why.pre_rows == kRingDefaultRows ? capacity_ : why.pre_rows;
}

void CaptureRing::commit() noexcept {
  ++written_;
  if (armed_ && written_ - trigger_ > post_) try_freeze();
}

void CaptureRing::try_freeze() noexcept {
  if (frozen_.load(std::memory_order_acquire) >= 0) {
    // The writer still holds the other buffer. Keep recording; give up only once the trigger row
    // itself is about to be overwritten.
    if (written_ - trigger_ >= capacity_) {
      armed_ = false;
      bump(dropped_);
    }
    return;
  }
  Buffer& b = buffers_[active_];
  b.capture.rows = b.rows.get();
  b.capture.capacity = capacity_;
  b.capture.end = written_;
  const std::uint64_t oldest = written_ > capacity_ ? written_ - capacity_ : 0;
  b.capture.first = std::max(oldest, trigger_ > pre_ ? trigger_ - pre_ : 0);
  b.capture.trigger = trigger_;
  b.capture.merged = merged_;
  b.capture.why = why_;
  frozen_.store(active_, std::memory_order_release);
  active_ ^= 1;
  written_ = 0;
  armed_ = false;
  bump(frozen_count_);
}

const Capture* CaptureRing::take() const noexcept {
  const int i = frozen_.load(std::memory_order_acquire);
  return i < 0 ? nullptr : &buffers_[i].capture;
}

void CaptureRing::release() noexcept { frozen_.store(-1, std::memory_order_release); }

CaptureRingCounts CaptureRing::counts() const noexcept {
  return {triggers_.load(std::memory_order_relaxed), frozen_count_.load(std::memory_order_relaxed),
          merged_count_.load(std::memory_order_relaxed), dropped_.load(std::memory_order_relaxed)};
}

}  // namespace hsa::daemon
