// One axis's port: every ring and buffer through which the LCM, operator and RT threads meet for
// this axis, in one vocabulary (the supervisor's SetpointInput, AxisCommand and CommandOutcome,
// the axis's telemetry, and port_messages.hpp).
//
//   LCM → RT         setpoints                  SpscRing<SetpointInput>
//   LCM → operator   commands, with whom to answer  SpscRing<OperatorCommand>
//   operator → RT    the commands the axis runs  SpscRing<AxisCommand>
//   RT → operator    the axis's answer to each   SpscRing<CommandOutcome>
//   RT → operator    the axis's latest state     TripleBuffer<AxisTelemetry>
//   RT → LCM         telemetry                   SpscRing<TelemetrySample>
//   operator → LCM   status                      SpscRing<StatusSample>
//
// Each ring has one producer thread and one consumer thread; every push and pop is wait-free,
// allocation-free and system-call-free. A full ring drops the new value and counts it; no thread
// ever waits for another. The LCM side's methods are private to LcmBridge (a friend).
//
// Counters are relaxed atomics: each is written by one thread and read by any (status, tests).
// They are cumulative since construction.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "daemon/axis/axis_telemetry.hpp"
#include "daemon/axis/port_messages.hpp"
#include "daemon/axis/reject_reason.hpp"
#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/operator_input.hpp"
#include "lockfree/spsc_ring.hpp"
#include "lockfree/triple_buffer.hpp"

namespace hsa::daemon {

// What a setpoint for one axis may ask for. Positions are the axis's configured range (its soft
// limits, or a stricter setpoint range); the speed limit applies to the velocity feed-forward.
struct AxisLimits {
  double min_position_m = 0.0;
  double max_position_m = 0.0;
  double max_velocity_m_s = std::numeric_limits<double>::infinity();

  // Finite min < max and a positive (possibly infinite) speed limit.
  [[nodiscard]] bool valid() const {
    return std::isfinite(min_position_m) && std::isfinite(max_position_m) && min_position_m < max_position_m &&
           !std::isnan(max_velocity_m_s) && max_velocity_m_s > 0.0;
  }
};

// Ring sizes, each a power of two. Setpoints: 100 ms at 10 kHz; telemetry: 100 ms at 10 kHz of
// pushes (the bridge drains every millisecond, so this is slack for a descheduled LCM thread).
// Commands and answers: far more than any operator sends between two polls of the operator thread.
struct RingCapacities {
  std::size_t setpoints = 1024;
  std::size_t commands = 64;
  std::size_t telemetry = 1024;
  std::size_t status = 64;
};

// A snapshot of an axis's counters. "Accepted" means validated and queued; a valid message that
// finds its ring full counts as a ring drop instead.
struct AxisCounters {
  std::uint64_t setpoints_accepted = 0;
  std::uint64_t commands_accepted = 0;
  std::array<std::uint64_t, kRejectReasonCount> rejected{};  // indexed by RejectReason; [none] = 0
  std::uint64_t lcm_seq_gaps = 0;
  std::uint64_t setpoint_ring_drops = 0;
  std::uint64_t command_ring_drops = 0;
  std::uint64_t telemetry_ring_drops = 0;
  std::uint64_t status_ring_drops = 0;
  std::uint64_t telemetry_published = 0;
  std::uint64_t status_published = 0;

  [[nodiscard]] std::uint64_t rejected_for(RejectReason reason) const {
    return rejected[static_cast<std::size_t>(reason)];
  }
  [[nodiscard]] std::uint64_t rejected_total() const {
    std::uint64_t total = 0;
    for (const auto n : rejected) total += n;
    return total;
  }
};

class AxisPort {
 public:
  AxisPort(std::string name, const AxisLimits& limits, const RingCapacities& capacities)
      : name_(std::move(name)),
        limits_(limits),
        setpoints_(capacities.setpoints),
        commands_(capacities.commands),
        to_axis_(capacities.commands),
        answers_(capacities.commands),
        telemetry_(capacities.telemetry),
        status_(capacities.status) {}

  AxisPort(const AxisPort&) = delete;
  AxisPort& operator=(const AxisPort&) = delete;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const AxisLimits& limits() const { return limits_; }

  // --- RT thread ---------------------------------------------------------------------------------
  bool pop_setpoint(SetpointInput& out) noexcept { return setpoints_.try_pop(out); }
  bool pop_axis_command(AxisCommand& out) noexcept { return to_axis_.try_pop(out); }
  // False when the ring is full (then the operator thread polls too seldom to hear it anyway).
  bool push_answer(const CommandOutcome& outcome) noexcept { return answers_.try_push(outcome); }
  void publish_latest(const AxisTelemetry& tm) noexcept { latest_.publish(tm); }
  // False (and counted) when the ring is full.
  bool push_telemetry(const TelemetrySample& sample) noexcept { return push_counted(telemetry_, sample, telemetry_ring_drops_); }

  // --- operator thread ---------------------------------------------------------------------------
  bool pop_command(OperatorCommand& out) noexcept { return commands_.try_pop(out); }
  bool push_axis_command(const AxisCommand& command) noexcept { return to_axis_.try_push(command); }
  bool pop_answer(CommandOutcome& out) noexcept { return answers_.try_pop(out); }
  // The RT thread's newest state, or nullptr when nothing new was published since the last take.
  const AxisTelemetry* take_latest() noexcept { return latest_.take(); }
  bool push_status(const StatusSample& sample) noexcept { return push_counted(status_, sample, status_ring_drops_); }

  // --- any thread --------------------------------------------------------------------------------
  [[nodiscard]] AxisCounters counters() const noexcept {
    AxisCounters c;
    c.setpoints_accepted = load(setpoints_accepted_);
    c.commands_accepted = load(commands_accepted_);
    for (std::size_t i = 0; i < kRejectReasonCount; ++i) c.rejected[i] = load(rejected_[i]);
    c.lcm_seq_gaps = load(lcm_seq_gaps_);
    c.setpoint_ring_drops = load(setpoint_ring_drops_);
    c.command_ring_drops = load(command_ring_drops_);
    c.telemetry_ring_drops = load(telemetry_ring_drops_);
    c.status_ring_drops = load(status_ring_drops_);
    c.telemetry_published = load(telemetry_published_);
    c.status_published = load(status_published_);
    return c;
  }

 private:
  friend class LcmBridge;
  using Counter = std::atomic<std::uint64_t>;
  static_assert(Counter::is_always_lock_free);

  static std::uint64_t load(const Counter& c) noexcept { return c.load(std::memory_order_relaxed); }
  static void bump(Counter& c, std::uint64_t n = 1) noexcept { c.fetch_add(n, std::memory_order_relaxed); }

  template <typename T>
  static bool push_counted(lockfree::SpscRing<T>& ring, const T& value, Counter& drops) noexcept {
    if (ring.try_push(value)) return true;
    bump(drops);
    return false;
  }

  // --- LCM thread (LcmBridge) ----------------------------------------------------------------------
  void offer_setpoint(const SetpointInput& setpoint) noexcept {
    if (push_counted(setpoints_, setpoint, setpoint_ring_drops_)) bump(setpoints_accepted_);
  }
  bool offer_command(const OperatorCommand& command) noexcept {
    if (!push_counted(commands_, command, command_ring_drops_)) return false;
    bump(commands_accepted_);
    return true;
  }
  // A command the LCM thread carries out itself (the lease's ACQUIRE and RELEASE).
  void count_command_done() noexcept { bump(commands_accepted_); }
  void count_reject(RejectReason reason) noexcept { bump(rejected_[static_cast<std::size_t>(reason)]); }
  void count_seq_gaps(std::uint64_t n) noexcept {
    if (n != 0) bump(lcm_seq_gaps_, n);
  }

  const std::string name_;
  const AxisLimits limits_;

  lockfree::SpscRing<SetpointInput> setpoints_;
  lockfree::SpscRing<OperatorCommand> commands_;
  lockfree::SpscRing<AxisCommand> to_axis_;
  lockfree::SpscRing<CommandOutcome> answers_;
  lockfree::TripleBuffer<AxisTelemetry> latest_;
  lockfree::SpscRing<TelemetrySample> telemetry_;
  lockfree::SpscRing<StatusSample> status_;

  Counter setpoints_accepted_{0};
  Counter commands_accepted_{0};
  std::array<Counter, kRejectReasonCount> rejected_{};
  Counter lcm_seq_gaps_{0};
  Counter setpoint_ring_drops_{0};
  Counter command_ring_drops_{0};
  // Written by the RT and operator threads: on their own line, away from the LCM thread's counters.
  alignas(lockfree::kCacheLineSize) Counter telemetry_ring_drops_{0};
  Counter status_ring_drops_{0};
  alignas(lockfree::kCacheLineSize) Counter telemetry_published_{0};
  Counter status_published_{0};
};

}  // namespace hsa::daemon
