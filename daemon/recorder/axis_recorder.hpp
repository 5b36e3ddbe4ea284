// The flight recorder's RT side for one axis: after each AxisLoop::cycle, one row of what the
// cycle did goes into the axis's CaptureRing, and the cycle in which the axis enters FAULT or
// ESTOP, or took an operator's CAPTURE command (apply), triggers it. The row is committed when the
// RT cycle ends, with the cycle's execution time, which is only known then (DaemonCycle); an armed
// condition (capture_condition.hpp) is evaluated then, on the complete row, so that it may watch
// exec_ns too.
//
// Nothing here allocates, locks or makes a system call: a row is a few stores into the ring's
// preallocated buffer (bench/bench_recorder.cpp measures the cost).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "daemon/axis/axis_loop.hpp"
#include "daemon/recorder/capture_condition.hpp"
#include "daemon/recorder/capture_ring.hpp"

namespace hsa::daemon {

// One row from a cycle's telemetry and the law's own states (all but exec_ns, which the end of the
// RT cycle writes). AxisRecorder::record uses it, and bench_recorder measures it.
void fill_row(RecorderRow& r, const AxisTelemetry& tm, double limited_setpoint_m, double integral,
              std::uint64_t seq, std::uint64_t tick, std::uint64_t skipped, std::int32_t lateness_ns) noexcept;

class AxisRecorder {
 public:
  explicit AxisRecorder(std::unique_ptr<CaptureRing> ring) : ring_(std::move(ring)) {}

  // RT thread, after loop.cycle(). `tick` is the cycle's base tick, `skipped` the periods the
  // executive skipped before it, `lateness_ns` its lateness.
  void record(const AxisLoop& loop, std::uint64_t tick, std::uint64_t skipped, std::int32_t lateness_ns) noexcept;
  // RT thread, at the end of the RT cycle: the row is complete; the armed condition looks at it.
  void commit(std::int32_t exec_ns) noexcept;
  // RT thread, before loop.cycle(): an operator's CAPTURE command, resolved by the operator thread
  // (capture_gate.hpp). now: this cycle's row is the trigger; arm: `request`'s condition replaces
  // any armed one; disarm: none is armed. `ticket` names the command (armed_ticket()).
  void apply(const CaptureRequest& request, std::uint64_t ticket) noexcept;
  // Any thread: the ticket of the command whose condition is armed now, 0 when none is (a
  // single-shot one that fired is no longer armed).
  [[nodiscard]] std::uint64_t armed_ticket() const noexcept { return armed_ticket_.load(std::memory_order_relaxed); }

  [[nodiscard]] CaptureRing& ring() noexcept { return *ring_; }
  [[nodiscard]] const CaptureRing& ring() const noexcept { return *ring_; }

 private:
  std::unique_ptr<CaptureRing> ring_;
  AxisState last_state_ = AxisState::init;
  std::uint64_t rows_ = 0;
  double kp_ = 0.0, ki_ = 0.0;  // this cycle's gains, for a condition's trigger
  FaultRecord fault_{};         // and its latched fault
  bool now_pending_ = false;    // a CAPTURE now waits for this cycle's row
  CaptureRequest now_{};
  CaptureCondition condition_;
  std::uint32_t condition_pre_ = kRingDefaultRows, condition_post_ = kRingDefaultRows;
  std::atomic<std::uint64_t> armed_ticket_{0};
};

}  // namespace hsa::daemon
