#include "tools/hsa_simdev/rig_runner.hpp"

#include "tools/hsa_simdev/period_timer.hpp"

namespace hsa::simdev {

RigRunner::RigRunner(const sim::RigConfig& config, double period_s) : rig_(config), period_s_(period_s) {
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

void RigRunner::set_inputs(const RigInputs& inputs) {
  const std::lock_guard lock(mutex_);
  inputs_ = inputs;
}

void RigRunner::set_can_valve(double command, bool enable) {
  const std::lock_guard lock(mutex_);
  can_valve_ = true;
  can_command_ = command;
  can_enable_ = enable;
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
      in = inputs_;
      if (can_valve_) {
        in.valve_command = can_command_;
        in.valve_enable = can_enable_;
      }
    }
    rig_.set_valve_command(in.valve_command);
    rig_.set_valve_enable(in.valve_enable);
    rig_.set_estop(in.estop_pressed);
    rig_.advance(period_s_);
    const RigOutputs out{rig_.read(), rig_.time_s()};
    {
      const std::lock_guard lock(mutex_);
      outputs_ = out;
    }
  }
}

}  // namespace hsa::simdev
