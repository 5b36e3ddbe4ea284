// One axis's connection between the LCM thread and the RT thread: four SPSC rings and counters.
//
// The RT side (one thread, the RT thread) pops setpoints and commands and pushes telemetry and
// status samples through the public members; every one of them is wait-free, allocation-free and
// system-call-free. The LCM side is LcmBridge (a friend), on its own thread. A full ring drops the
// new value and counts it; the RT thread never waits for the LCM thread and vice versa.
//
// Counters are relaxed atomics: each is written by one thread and read by any (status, tests).
// They are cumulative since construction.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "daemon/lcm_bridge/message_validation.hpp"
#include "daemon/lcm_bridge/rt_messages.hpp"
#include "daemon/lcm_bridge/spsc_ring.hpp"

namespace hsa::daemon {

// Ring sizes, each a power of two. Setpoints: 100 ms at 10 kHz; telemetry: 100 ms at 10 kHz of
// pushes (the bridge drains every millisecond, so this is slack for a descheduled LCM thread).
struct RingCapacities {
  std::size_t setpoints = 1024;
  std::size_t commands = 64;
  std::size_t telemetry = 1024;
  std::size_t status = 64;
};

// A snapshot of an axis's counters. "Accepted" means validated and queued to the RT thread; a
// valid message that finds its ring full counts as a ring drop instead.
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
        telemetry_(capacities.telemetry),
        status_(capacities.status) {}

  AxisPort(const AxisPort&) = delete;
  AxisPort& operator=(const AxisPort&) = delete;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const AxisLimits& limits() const { return limits_; }

  // --- RT thread ---------------------------------------------------------------------------------
  bool pop_setpoint(SetpointMsg& out) noexcept { return setpoints_.try_pop(out); }
  bool pop_command(CommandMsg& out) noexcept { return commands_.try_pop(out); }
  // False (and counted) when the ring is full.
  bool push_telemetry(const TelemetrySample& sample) noexcept { return push_counted(telemetry_, sample, telemetry_ring_drops_); }
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
  static bool push_counted(SpscRing<T>& ring, const T& value, Counter& drops) noexcept {
    if (ring.try_push(value)) return true;
    bump(drops);
    return false;
  }

  // --- LCM thread (LcmBridge) ----------------------------------------------------------------------
  void offer_setpoint(const SetpointMsg& msg) noexcept {
    if (push_counted(setpoints_, msg, setpoint_ring_drops_)) bump(setpoints_accepted_);
  }
  bool offer_command(const CommandMsg& msg) noexcept {
    if (!push_counted(commands_, msg, command_ring_drops_)) return false;
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

  SpscRing<SetpointMsg> setpoints_;
  SpscRing<CommandMsg> commands_;
  SpscRing<TelemetrySample> telemetry_;
  SpscRing<StatusSample> status_;

  Counter setpoints_accepted_{0};
  Counter commands_accepted_{0};
  std::array<Counter, kRejectReasonCount> rejected_{};
  Counter lcm_seq_gaps_{0};
  Counter setpoint_ring_drops_{0};
  Counter command_ring_drops_{0};
  // Written by the RT thread: on their own line, away from the LCM thread's counters.
  alignas(kCacheLineSize) Counter telemetry_ring_drops_{0};
  Counter status_ring_drops_{0};
  alignas(kCacheLineSize) Counter telemetry_published_{0};
  Counter status_published_{0};
};

}  // namespace hsa::daemon
