// A charge-pump output, as LinuxCNC's `charge_pump` component provides: a square wave on a GPIO
// line that an external safety relay (a charge-pump watchdog board) watches. The relay holds its
// contacts only while the line keeps toggling, so when the real-time thread stops (hsad killed,
// stopped, hung, or the driver deactivated or in error) the line stops toggling and the relay
// drops the valve power in hardware, whatever the PC does next.
//
// Algorithm. While the driver is active, every write() call is one step: every `divisor`-th step
// inverts the level, so the line is a square wave of period 2 * divisor cycles (hsad writes once
// per base tick: at 100 µs and divisor 1, 5 kHz). Stopped (configure, deactivate, error) it sits at
// its safe level and the count restarts, so the first edge after activation comes `divisor`
// steps later: the level is a pure function of the steps since the last stop.
//
// Plain state, no system call: the driver sets the line to level() itself. Nothing allocates,
// locks or blocks.
#pragma once

#include <cstdint>

namespace hsa::io::gpiod {

class ChargePump {
 public:
  // divisor >= 1 (the settings check it); safe_level: the level while stopped.
  explicit ChargePump(std::uint32_t divisor = 1, bool safe_level = false) noexcept
      : divisor_(divisor == 0 ? 1 : divisor), safe_(safe_level), level_(safe_level) {}

  // One write() cycle while active; returns the level to drive.
  bool step() noexcept {
    if (++count_ >= divisor_) {
      count_ = 0;
      level_ = !level_;
    }
    return level_;
  }

  // Deactivated, in error or not yet active: back to the safe level; returns it.
  bool stop() noexcept {
    count_ = 0;
    level_ = safe_;
    return level_;
  }

  [[nodiscard]] bool level() const noexcept { return level_; }
  [[nodiscard]] std::uint32_t divisor() const noexcept { return divisor_; }

 private:
  std::uint32_t divisor_;
  bool safe_;
  bool level_;
  std::uint32_t count_ = 0;
};

}  // namespace hsa::io::gpiod
