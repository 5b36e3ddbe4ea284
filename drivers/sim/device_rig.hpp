// A simulated rig run as a device runs: on its own clock, in the sim plugin's device thread
// (device_clock.hpp), with the RT thread meeting it only through a mailbox, as it meets a bus
// driver's thread.
//
// Why: with `timing = "cycle"` or `"lockstep"` the rig model steps inside the RT thread's read(),
// so every axis's tick carries the model's cost (about 0.5 µs a step with the proportional valve),
// which no real rig costs the daemon. Run on the device thread instead, the RT thread pays for a
// read of the latest readings and a store of the command, and what it measures per axis is the
// daemon's own work (bench/axes-per-core --rig-thread).
//
// The mailbox: the readings after each device step go to the RT thread through a triple buffer
// (wait-free both ways; the RT thread never waits for a step), and the command and the valve
// enable come back as atomics that the device latches before each step. A make_safe() or a lost
// bus therefore reaches the rig at its next step, one step_s later at most, as a valve
// amplifier's watchdog acts on its own clock.
#pragma once

#include <atomic>
#include <cstdint>

#include "lockfree/triple_buffer.hpp"
#include "sim/rig.hpp"

namespace hsa::io::sim_plugin {

class DeviceRig {
 public:
  // `rig` must outlive the DeviceRig's attachment to the device clock.
  explicit DeviceRig(sim::Rig& rig) : rig_(rig), readings_(rig.read()) {}
  DeviceRig(const DeviceRig&) = delete;
  DeviceRig& operator=(const DeviceRig&) = delete;

  // The RT side (wait-free, no allocation).
  void set_command(double command) noexcept { command_.store(command, std::memory_order_relaxed); }
  void set_enable(bool enabled) noexcept { enable_.store(enabled, std::memory_order_relaxed); }
  // The readings of the device's latest step.
  const sim::RigReadings& latest() noexcept {
    (void)readings_.fetch();
    return readings_.front();
  }
  // Device steps so far (tests and diagnostics).
  [[nodiscard]] std::uint64_t steps() const noexcept { return steps_.load(std::memory_order_relaxed); }

  // The device thread's side: latch the inputs, step the model, publish what its sensors read.
  void step() noexcept {
    rig_.set_valve_command(command_.load(std::memory_order_relaxed));
    rig_.set_valve_enable(enable_.load(std::memory_order_relaxed));
    rig_.step();
    readings_.publish(rig_.read());
    steps_.fetch_add(1, std::memory_order_relaxed);
  }

 private:
  sim::Rig& rig_;
  lockfree::TripleBuffer<sim::RigReadings> readings_;
  std::atomic<double> command_{0.0};
  std::atomic<bool> enable_{false};
  std::atomic<std::uint64_t> steps_{0};
  static_assert(std::atomic<double>::is_always_lock_free, "the RT side must never take a lock");
};

}  // namespace hsa::io::sim_plugin
