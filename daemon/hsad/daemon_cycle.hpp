// hsad's work on the real-time thread, once per base tick (docs/architecture.md, "Data flow"):
//
//   read every driver → for each axis: take the newest setpoint and any forwarded command,
//   run the supervisor and the loops (AxisLoop) → write every driver → make_safe on every driver
//   whose read or write failed in this cycle → hand telemetry out.
//
// A failed driver gets no more read or write, so the safe command and enable-off that the axes
// computed in this cycle would never reach it: make_safe does it, in the same cycle, once per
// failure (the driver keeps its outputs safe until it is activated again).
//
// Nothing here allocates, locks or blocks: setpoints come from the LCM bridge's SPSC ring,
// commands from the operator thread's SPSC ring, telemetry leaves through the bridge's ring
// (decimated on the tick index) and, for the operator thread's status reports, through a
// wait-free triple buffer per axis. Gain changes do not come this way: the operator thread
// hands them to AxisLoop::request_gains, which applies them at a cycle boundary.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "daemon/hsad/driver_set.hpp"
#include "daemon/hsad/tick_decimator.hpp"
#include "daemon/lcm_bridge/axis_port.hpp"
#include "daemon/lcm_bridge/spsc_ring.hpp"
#include "daemon/rt/cycle_task.hpp"
#include "daemon/service/systemd_watchdog.hpp"
#include "daemon/axis/axis_loop.hpp"
#include "drivers/triple_buffer.hpp"

namespace hsa::daemon {

// A command for the RT thread, from the operator thread (which consumes the LCM commands).
struct ForwardedCommand {
  CommandKind kind = CommandKind::none;
  ControlMode mode = ControlMode::position;
  bool has_opening = false;  // open-loop mode: the commanded valve opening
  double opening = 0.0;
  MoveRequest move;          // move_to
  std::uint64_t ticket = 0;  // the operator thread's, to match the axis's answer to the sender
};

// Timing of this axis's cycles, carried into telemetry.
struct CycleTimingStats {
  std::int32_t lateness_ns = 0;
  std::int32_t lateness_max_ns = 0;
  std::int32_t exec_ns = 0;
  std::int32_t exec_max_ns = 0;
  std::int64_t overruns = 0;
};

struct AxisRuntime {
  AxisRuntime(std::unique_ptr<AxisLoop> loop, AxisPort& port, std::uint64_t driver_mask)
      : loop(std::move(loop)), port(port), driver_mask(driver_mask), commands(64) {}

  std::unique_ptr<AxisLoop> loop;
  AxisPort& port;
  std::uint64_t driver_mask;  // the drivers this axis uses
  SpscRing<ForwardedCommand> commands;
  io::TripleBuffer<AxisTelemetry> latest;  // RT → operator thread
  AxisInputsFromOperator op{};         // RT-thread state: what the axis is following
  TickDecimator telemetry{1};  // which cycles publish telemetry (the axis's ticks_per_telemetry)
};

class DaemonCycle final : public CycleTask {
 public:
  DaemonCycle(DriverSet& drivers, std::vector<std::unique_ptr<AxisRuntime>>& axes, SystemdWatchdog& watchdog);

  void cycle(const CycleTiming& timing) noexcept override;

  // After the RT thread has stopped: one last cycle on the caller's thread that disables every
  // axis and then calls make_safe on every driver, so the valves end in their safe state before
  // the drivers deactivate.
  void drive_safe(std::int64_t t_ns) noexcept;

  [[nodiscard]] std::int64_t epoch_ns() const { return epoch_ns_; }

 private:
  void run_axes(std::int64_t t_ns, std::uint64_t tick, std::uint64_t failed_drivers, std::uint32_t streak) noexcept;

  DriverSet& drivers_;
  std::vector<std::unique_ptr<AxisRuntime>>& axes_;
  SystemdWatchdog& watchdog_;
  std::int64_t epoch_ns_;
  std::int64_t last_ns_ = 0;
  std::uint64_t failed_writes_ = 0;  // drivers whose last write failed
  std::uint64_t made_safe_ = 0;      // drivers out of the cycle that already got their make_safe
  CycleTimingStats timing_{};
};

}  // namespace hsa::daemon
