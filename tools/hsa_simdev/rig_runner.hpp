// The simulated rig advancing in real time on its own thread, paced by clock_nanosleep
// (CLOCK_MONOTONIC, TIMER_ABSTIME) at a fixed period, each period stepping the rig by that much
// simulated time.
//
// The Modbus server thread exchanges values with it through a mutex-protected snapshot: this is a
// tool, not the daemon's RT path, and a lock held for a struct copy is cheaper than anything
// cleverer. When the process falls far behind (a stopped debugger, an overloaded machine) the
// runner skips ahead instead of racing to catch up, and counts the skips.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <thread>

#include "sim/rig.hpp"

namespace hsa::simdev {

struct RigInputs {
  double valve_command = 0.0;
  bool valve_enable = false;
  bool estop_pressed = false;
};

struct RigOutputs {
  sim::RigReadings readings{};
  double time_s = 0.0;
};

class RigRunner {
 public:
  RigRunner(const sim::RigConfig& config, double period_s);
  ~RigRunner();  // stops the thread
  RigRunner(const RigRunner&) = delete;
  RigRunner& operator=(const RigRunner&) = delete;

  void start();
  void stop();

  void set_inputs(const RigInputs& inputs);
  // The valve command and enable from the CAN bus (can_server.hpp). From the first call on they
  // take precedence over those of set_inputs: two masters on one valve would fight, and a
  // controller that talks CAN to the valve does not write the Modbus register.
  void set_can_valve(double command, bool enable);
  [[nodiscard]] RigOutputs outputs() const;
  [[nodiscard]] std::uint64_t skips() const { return skips_.load(std::memory_order_relaxed); }

 private:
  void run(std::stop_token stop);

  sim::Rig rig_;  // the runner thread's alone once started
  double period_s_;
  mutable std::mutex mutex_;
  RigInputs inputs_;    // guarded by mutex_
  RigOutputs outputs_;  // guarded by mutex_
  bool can_valve_ = false;  // guarded by mutex_: set_can_valve was called
  double can_command_ = 0.0;
  bool can_enable_ = false;
  std::atomic<std::uint64_t> skips_{0};
  std::jthread thread_;
};

}  // namespace hsa::simdev
