// hsad's work on the real-time thread, once per base tick (docs/architecture.md, "Data flow"):
//
//   read every driver → for each axis: take the newest setpoint and the next command the operator
//   thread passed on (a CAPTURE goes to the axis's flight recorder), run the supervisor and the
//   loops (AxisLoop), hand the axis's answer to that command back, and fill the cycle's row of the axis's flight recorder (daemon/recorder) → write
//   every driver → make_safe on every driver whose read or write failed in this cycle → hand
//   telemetry out → complete the recorder rows with the cycle's execution time.
//
// A failed driver gets no more read or write, so the safe command and enable-off that the axes
// computed in this cycle would never reach it: make_safe does it, in the same cycle, once per
// failure (the driver keeps its outputs safe until it is activated again).
//
// Nothing here allocates, locks or blocks: everything crosses the axis's port (axis_port.hpp),
// whose rings and triple buffer are wait-free. Gain changes do not come this way: the operator
// thread hands them to AxisLoop::request_gains, which applies them at a cycle boundary.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "daemon/axis/axis_runtime.hpp"
#include "daemon/hsad/driver_set.hpp"
#include "daemon/rt/cycle_task.hpp"
#include "daemon/service/systemd_watchdog.hpp"

namespace hsa::daemon {

// Timing of this axis's cycles, carried into telemetry.
struct CycleTimingStats {
  std::int32_t lateness_ns = 0;
  std::int32_t lateness_max_ns = 0;
  std::int32_t exec_ns = 0;
  std::int32_t exec_max_ns = 0;
  std::int64_t overruns = 0;
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
  std::uint64_t skipped_ = 0;  // periods skipped before this cycle (the flight recorder's rows)
  AxisCommand command_{};      // the command taken this cycle, before it goes to its axis
};

}  // namespace hsa::daemon
