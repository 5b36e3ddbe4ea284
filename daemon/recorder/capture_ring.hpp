// The flight recorder's ring of one axis: the last N rows of its RT cycles (recorder_row.hpp),
// always armed, frozen around a trigger and handed to a normal thread that writes the capture file.
//
// Handoff: two buffers of N rows, both allocated and written (so their pages exist, and are locked
// by hsad's mlockall) in the constructor. The RT thread writes into the active one; a trigger
// marks the row being written; once post_rows more rows are committed, the RT thread freezes the
// active buffer (its window and trigger go into the buffer's Capture), publishes its index in
// `frozen_` with a release store, and goes on writing into the other buffer, from empty. The writer
// thread takes the capture with an acquire load, reads it at leisure, and gives the buffer back
// with a release store of "none"; only then may the RT thread freeze again (acquire load). So the
// two threads never touch the same buffer at the same time: no row can be torn, nothing is copied
// on the RT thread, and neither thread ever waits for the other (no lock, no syscall, no
// allocation: a freeze is a few stores and one atomic store).
//
// The price is that the next capture's pre-trigger history starts at the freeze: a second fault
// within `capacity` rows of the first has less than the full pre-trigger window (its file says
// so: fewer rows before its trigger). A trigger while a capture is collecting its post-trigger
// rows falls inside that capture's window and is counted (merged). When the post-trigger rows are
// in but the writer still holds the other buffer, the RT thread keeps recording and freezes as
// soon as the buffer comes back; only if the trigger row would be overwritten first is the
// capture given up and counted (dropped). Nothing is lost without a count.
//
// An operator's trigger may ask for a shorter history or a longer (or shorter) post-trigger
// window than the configured one, within the ring (pre + 1 + post rows at most: capture_gate.hpp).
//
// Rows are addressed by their index in the active buffer's write count (0, 1, ...): the row of
// index i lives at rows[i % capacity].
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "daemon/recorder/recorder_row.hpp"
#include "daemon/supervisor/axis_state.hpp"
#include "daemon/supervisor/capture_request.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

// fault: the axis entered FAULT or ESTOP; request: an operator asked for a capture now
// (command_t.CAPTURE); condition: an operator's condition on a signal fired (capture_condition.hpp).
enum class TriggerKind : std::uint8_t { fault, request, condition };

// Why a capture was taken, as the RT thread saw it in the trigger's cycle.
struct CaptureTrigger {
  TriggerKind kind = TriggerKind::fault;
  AxisState state = AxisState::fault;  // fault: the state entered (fault or estop); else the state then
  FaultRecord fault{};                 // the latched record (reason none: healthy, or an e-stop)
  std::uint64_t tick = 0;              // the trigger row's base tick
  std::int64_t t_ns = 0;               // its cycle time on the daemon's clock
  double kp = 0.0;                     // the PI gains in use then
  double ki = 0.0;
  // Rows kept before the trigger row and collected after it (kRingDefaultRows: the whole ring
  // before, the ring's post_rows after). pre + 1 + post must fit the ring (capture_gate checks an
  // operator's; the ring clamps what does not).
  std::uint32_t pre_rows = kRingDefaultRows;
  std::uint32_t post_rows = kRingDefaultRows;
  // condition: which signal crossed which level, which way (capture_condition.hpp's ConditionSpec).
  int signal = -1;
  Crossing crossing = Crossing::above;
  double level = 0.0;
};

// A frozen window, owned by the writer between take() and release().
struct Capture {
  const RecorderRow* rows = nullptr;
  std::size_t capacity = 0;
  std::uint64_t first = 0;    // index of the oldest row held
  std::uint64_t end = 0;      // one past the newest
  std::uint64_t trigger = 0;  // index of the trigger row, in [first, end)
  std::uint64_t merged = 0;   // further triggers inside this window
  CaptureTrigger why{};

  [[nodiscard]] std::size_t size() const noexcept { return static_cast<std::size_t>(end - first); }
  // The k-th row of the window (0: the oldest).
  [[nodiscard]] const RecorderRow& row(std::size_t k) const noexcept { return rows[(first + k) % capacity]; }
  [[nodiscard]] std::size_t trigger_offset() const noexcept { return static_cast<std::size_t>(trigger - first); }
};

// Counted on the RT thread, read anywhere (relaxed).
struct CaptureRingCounts {
  std::uint64_t triggers = 0;  // every trigger, merged ones included
  std::uint64_t frozen = 0;    // captures handed to the writer
  std::uint64_t merged = 0;    // triggers that fell into a capture still collecting its post-trigger rows
  std::uint64_t dropped = 0;   // captures given up: the writer held the other buffer too long
};

class CaptureRing {
 public:
  // Throws std::invalid_argument unless 2 <= rows and post_rows < rows.
  CaptureRing(std::size_t rows, std::size_t post_rows);

  CaptureRing(const CaptureRing&) = delete;
  CaptureRing& operator=(const CaptureRing&) = delete;

  // RT thread. slot() is the row of this cycle, filled in place; commit() ends it. A trigger
  // marks the row of the current slot (call it between slot() and commit()); its pre_rows and
  // post_rows shape the window (a capture holds at most pre_rows rows before its trigger row).
  [[nodiscard]] RecorderRow& slot() noexcept { return buffers_[active_].rows[written_ % capacity_]; }
  void trigger(const CaptureTrigger& why) noexcept;
  void commit() noexcept;
  // Any thread: ask for a capture at the next cycle (an operator's request). RT thread: take it.
  void request_manual() noexcept { manual_.store(true, std::memory_order_relaxed); }
  [[nodiscard]] bool take_manual_request() noexcept {
    return manual_.load(std::memory_order_relaxed) && manual_.exchange(false, std::memory_order_relaxed);
  }

  // Writer thread (one). take() returns the frozen capture or nullptr; release() gives it back.
  [[nodiscard]] const Capture* take() const noexcept;
  void release() noexcept;

  [[nodiscard]] CaptureRingCounts counts() const noexcept;
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  [[nodiscard]] std::size_t post_rows() const noexcept { return post_rows_; }
  [[nodiscard]] bool armed() const noexcept { return armed_; }  // RT thread

 private:
  struct Buffer {
    std::unique_ptr<RecorderRow[]> rows;
    Capture capture;
  };
  void try_freeze() noexcept;
  static void bump(std::atomic<std::uint64_t>& c) noexcept {
    c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // one writer
  }

  const std::size_t capacity_;
  const std::size_t post_rows_;
  Buffer buffers_[2];
  // RT thread's own.
  int active_ = 0;
  std::uint64_t written_ = 0;  // rows committed into the active buffer
  bool armed_ = false;         // a trigger waits for its post-trigger rows
  std::uint64_t trigger_ = 0;
  std::uint64_t post_ = 0;     // the armed trigger's post-trigger rows
  std::uint64_t pre_ = 0;      // and the history it keeps before its row
  std::uint64_t merged_ = 0;
  CaptureTrigger why_{};
  // Shared.
  std::atomic<int> frozen_{-1};  // the buffer the writer holds, or -1
  std::atomic<bool> manual_{false};
  std::atomic<std::uint64_t> triggers_{0}, frozen_count_{0}, merged_count_{0}, dropped_{0};
};

}  // namespace hsa::daemon
