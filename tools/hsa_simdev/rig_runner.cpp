#include "tools/hsa_simdev/rig_runner.hpp"

#include <time.h>

#include <cerrno>
#include <cmath>

namespace hsa::simdev {
namespace {

constexpr std::int64_t ns_per_s = 1'000'000'000;

std::int64_t to_ns(const timespec& t) { return t.tv_sec * ns_per_s + t.tv_nsec; }
timespec from_ns(std::int64_t ns) { return {static_cast<time_t>(ns / ns_per_s), static_cast<long>(ns % ns_per_s)}; }

std::int64_t now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return to_ns(t);
}

}  // namespace

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
  const auto period_ns = static_cast<std::int64_t>(std::llround(period_s_ * 1e9));
  std::int64_t next = now_ns();
  while (!stop.stop_requested()) {
    next += period_ns;
    const timespec deadline = from_ns(next);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
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
    // More than 100 periods behind: skip ahead rather than run the model in a burst.
    if (now_ns() - next > 100 * period_ns) {
      next = now_ns();
      skips_.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

}  // namespace hsa::simdev
