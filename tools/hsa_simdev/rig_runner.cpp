#include "tools/hsa_simdev/rig_runner.hpp"

#include <cmath>

#include "drivers/clock.hpp"
#include "tools/hsa_simdev/period_timer.hpp"

namespace hsa::simdev {

namespace {
constexpr double safe_command = 0.0;  // with the enable off: servo opening 0, solenoid current 0
}  // namespace

RigRunner::RigRunner(const sim::RigConfig& config, double period_s, double watchdog_s, EstopWiring estop)
    : rig_(config),
      period_s_(period_s),
      watchdog_(static_cast<std::int64_t>(std::llround(watchdog_s * 1e9))),
      estop_wiring_(estop) {
  // The amplifier starts unpowered, like the coil that commands it.
  rig_.set_valve_enable(false);
  outputs_ = {rig_.read(), rig_.time_s()};
}

RigRunner::~RigRunner() { stop(); }

void RigRunner::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(std::move(stop)); });
}

void RigRunner::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

RigInputs RigRunner::set_inputs(const RigInputs& inputs, const MasterWrite& write) {
  const std::int64_t now = io::monotonic_ns();
  const std::lock_guard lock(mutex_);
  inputs_ = inputs;
  const bool wrote_enable_off = write.wrote_enable && !inputs.valve_enable;
  if (!can_valve_ && write.any) {
    watchdog_.feed(now);
    if (watchdog_.tripped() && wrote_enable_off) watchdog_.acknowledge();
  }
  update_estop_cut_locked(!can_valve_ && wrote_enable_off);
  if (watchdog_.tripped()) {
    inputs_.valve_command = safe_command;
    inputs_.valve_enable = false;
  }
  return inputs_;
}

void RigRunner::set_can_valve(double command, bool enable) {
  const std::int64_t now = io::monotonic_ns();
  const std::lock_guard lock(mutex_);
  can_valve_ = true;
  watchdog_.feed(now);
  if (watchdog_.tripped() && !enable) watchdog_.acknowledge();
  update_estop_cut_locked(!enable);
  can_command_ = watchdog_.tripped() ? safe_command : command;
  can_enable_ = watchdog_.tripped() ? false : enable;
}

void RigRunner::check_can_watchdog() {
  const std::lock_guard lock(mutex_);
  if (can_valve_) check_watchdog_locked();
}

void RigRunner::check_watchdog_locked() {
  if (watchdog_.check(io::monotonic_ns())) {
    inputs_.valve_command = can_command_ = safe_command;
    inputs_.valve_enable = can_enable_ = false;
  }
}

void RigRunner::update_estop_cut_locked(bool master_wrote_enable_off) {
  if (estop_wiring_ != EstopWiring::cuts_valve_power) return;
  if (inputs_.estop_pressed) {
    valve_power_cut_ = true;
  } else if (master_wrote_enable_off) {
    valve_power_cut_ = false;  // released, and the master has taken its enable back: the reset
  }
}

bool RigRunner::valve_power_cut() const {
  const std::lock_guard lock(mutex_);
  return valve_power_cut_;
}

WatchdogState RigRunner::watchdog() const {
  const std::lock_guard lock(mutex_);
  return {watchdog_.enabled(), watchdog_.tripped(), watchdog_.trips()};
}

void RigRunner::enable_delay_probe(const DelayProbeSettings& settings) {
  const std::lock_guard lock(mutex_);
  probe_.emplace(settings);
}

void RigRunner::note_valve_command(double command, std::int64_t now_ns) {
  const std::lock_guard lock(mutex_);
  if (probe_) probe_->on_command(command, now_ns);
}

std::optional<DelayProbe> RigRunner::delay_probe() const {
  const std::lock_guard lock(mutex_);
  return probe_;
}

RigOutputs RigRunner::outputs() const {
  const std::lock_guard lock(mutex_);
  return outputs_;
}

void RigRunner::run(std::stop_token stop) {
  PeriodTimer timer(period_s_);
  while (!stop.stop_requested()) {
    // Far behind, the timer skips ahead rather than run the model in a burst.
    if (timer.wait_next()) skips_.fetch_add(1, std::memory_order_relaxed);
    RigInputs in;
    {
      const std::lock_guard lock(mutex_);
      if (!can_valve_) check_watchdog_locked();
      in = inputs_;
      if (can_valve_) {
        in.valve_command = can_command_;
        in.valve_enable = can_enable_;
      }
      if (valve_power_cut_) in.valve_enable = false;
    }
    rig_.set_valve_command(in.valve_command);
    rig_.set_valve_enable(in.valve_enable);
    rig_.set_estop(in.estop_pressed);
    rig_.advance(period_s_);
    RigOutputs out{rig_.read(), rig_.time_s()};
    {
      const std::int64_t sampled_ns = io::monotonic_ns();  // the sample's time, for the probe
      const std::lock_guard lock(mutex_);
      if (probe_ && out.readings.encoder_m.connected) out.readings.encoder_m.value += probe_->offset_at_tick(sampled_ns);
      outputs_ = out;
    }
  }
}

}  // namespace hsa::simdev
