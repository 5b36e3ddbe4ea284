// One running axis as hsad's threads share it: its loop (run by the RT thread), its port (where
// the LCM, operator and RT threads meet), the drivers its signals use, and the RT thread's own
// per-axis state.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>

#include "daemon/axis/axis_loop.hpp"
#include "daemon/axis/axis_port.hpp"
#include "daemon/axis/tick_decimator.hpp"
#include "daemon/recorder/axis_recorder.hpp"
#include "daemon/supervisor/operator_input.hpp"

namespace hsa::daemon {

struct AxisRuntime {
  AxisRuntime(std::unique_ptr<AxisLoop> loop, AxisPort& port, std::uint64_t driver_mask)
      : loop(std::move(loop)), port(port), driver_mask(driver_mask) {}

  std::unique_ptr<AxisLoop> loop;
  AxisPort& port;
  std::uint64_t driver_mask;  // the drivers this axis uses
  AxisInputsFromOperator op{};  // RT-thread state: the setpoint and command the axis is following
  TickDecimator telemetry{1};   // which cycles publish telemetry (the axis's ticks_per_telemetry)
  std::unique_ptr<AxisRecorder> recorder;  // the flight recorder's ring; none in some tests
};

}  // namespace hsa::daemon
