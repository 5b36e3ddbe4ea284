// hsad's threads' objects as main.cpp joins them (DriverSet, AxisLoop, DaemonCycle,
// OperatorService), without the RT thread and without LCM: the test thread plays the RT thread
// (DaemonCycle::cycle) and the operator thread (OperatorService::poll) in turn, so every
// interleaving is deterministic.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "daemon/axis/axis_signals.hpp"
#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"
#include "daemon/hsad/daemon_cycle.hpp"
#include "daemon/hsad/driver_set.hpp"
#include "daemon/hsad/operator_service.hpp"

namespace hsa::daemon::test {

class HsadPieces {
 public:
  static constexpr std::int64_t kPeriodNs = 100'000;

  // The operator thread polls after every `cycles_per_poll`-th cycle (hsad: every 100).
  explicit HsadPieces(const DaemonConfig& config, int cycles_per_poll = 1)
      : config_(config), drivers_(config_), cycles_per_poll_(cycles_per_poll) {
    const std::vector<io::DriverHandle*> handles = drivers_.handles();
    for (const AxisConfig& a : config_.axes) {
      const AxisParams params = axis_params(a, config_.realtime);
      AxisLimits limits;
      limits.min_position_m = a.limits.min_m;
      limits.max_position_m = a.limits.max_m;
      ports_.push_back(std::make_unique<AxisPort>(a.name, limits, RingCapacities{}));
      axes_.push_back(std::make_unique<AxisRuntime>(
          std::make_unique<AxisLoop>(params, bind_axis_signals(a.name, params.bindings, handles)),
          *ports_.back(), drivers_.mask_of(drivers_of(a))));
      axes_.back()->telemetry = TickDecimator(10);
      axes_.back()->recorder = std::make_unique<AxisRecorder>(
          std::make_unique<CaptureRing>(a.recorder.rows, a.recorder.post_rows));
    }
    drivers_.activate_all();
    cycle_ = std::make_unique<DaemonCycle>(drivers_, axes_, watchdog_);
    executive_ = std::make_unique<RtExecutive>(RtConfig{}, *cycle_);
    operators_ = std::make_unique<OperatorService>(axes_, drivers_, *executive_, RtConfig{}, RealtimeGrant{});
  }
  virtual ~HsadPieces() = default;

  void run(int n) {
    for (int i = 0; i < n; ++i) {
      ++tick_;
      const std::int64_t t = cycle_->epoch_ns() + static_cast<std::int64_t>(tick_) * kPeriodNs;
      cycle_->cycle(CycleTiming{t, t, kPeriodNs, tick_, 0, 0});
      if (tick_ % static_cast<std::uint64_t>(cycles_per_poll_) == 0) poll();
    }
  }
  // Runs until `axis` is in `state`, at most `n` cycles; true when it got there.
  bool run_until(std::size_t axis, AxisState state, int n) {
    for (int i = 0; i < n && telemetry(axis).state != state; ++i) run(1);
    return telemetry(axis).state == state;
  }
  virtual void poll() { operators_->poll(); }

  [[nodiscard]] const AxisTelemetry& telemetry(std::size_t axis) const { return axes_[axis]->loop->telemetry(); }
  OperatorService& operators() { return *operators_; }
  DriverSet& drivers() { return drivers_; }
  AxisPort& port(std::size_t axis) { return *ports_[axis]; }
  CaptureRing& recorder(std::size_t axis) { return axes_[axis]->recorder->ring(); }
  [[nodiscard]] std::int64_t epoch_ns() const { return cycle_->epoch_ns(); }
  io::DriverHandle& rig() { return *drivers_.handles()[0]; }

 private:
  DaemonConfig config_;
  DriverSet drivers_;
  int cycles_per_poll_;
  std::vector<std::unique_ptr<AxisPort>> ports_;
  std::vector<std::unique_ptr<AxisRuntime>> axes_;
  SystemdWatchdog watchdog_;
  std::unique_ptr<DaemonCycle> cycle_;
  std::unique_ptr<RtExecutive> executive_;
  std::unique_ptr<OperatorService> operators_;
  std::uint64_t tick_ = 0;
};

}  // namespace hsa::daemon::test
