// The operator's side of hsad, on a normal thread: commands from LCM are turned into what the RT
// thread understands (enable, disable, reset and mode go through a ring; gain changes go to
// AxisLoop::request_params, which applies them at a cycle boundary), and status is composed from
// each axis's latest telemetry and the executive's counters. Fault texts are formatted here,
// never on the RT thread.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "daemon/hsad/daemon_cycle.hpp"
#include "daemon/rt/realtime_grant.hpp"
#include "daemon/rt/rt_config.hpp"
#include "daemon/rt/rt_executive.hpp"

namespace hsa::daemon {

class OperatorService {
 public:
  OperatorService(std::vector<std::unique_ptr<AxisRuntime>>& axes, const RtExecutive& executive,
                  const RtConfig& rt, const RealtimeGrant& grant);

  void poll();  // commands in, status out; call at ~100 Hz

  [[nodiscard]] std::uint64_t gain_changes_refused() const { return gains_refused_; }

 private:
  void handle_commands(AxisRuntime& axis);
  [[nodiscard]] StatusSample status_of(const AxisTelemetry& tm, const RtStats& rt) const;

  std::vector<std::unique_ptr<AxisRuntime>>& axes_;
  const RtExecutive& executive_;
  RtConfig rt_;
  RealtimeGrant grant_;
  std::vector<AxisTelemetry> latest_;
  std::uint64_t gains_refused_ = 0;
};

}  // namespace hsa::daemon
