// A charge-pump output, as LinuxCNC's `charge_pump` component provides: a square wave on a GPIO
// line that an external safety relay (a charge-pump watchdog board) watches. The relay holds its
// contacts only while the line keeps toggling, so it drops the valve power in hardware whenever
// the wave stops: when the real-time thread stops (hsad killed, stopped, hung, or the driver
// deactivated or in error), and, through the enable, whenever the valve is not being driven.
//
// Algorithm. While the driver is active, every write() call is one step. A step with the enable
// on counts, and every `divisor`-th counted step inverts the level, so the line is a square wave
// of period 2 * divisor cycles (hsad writes once per base tick: at 100 µs and divisor 1, 5 kHz).
// A step with the enable off is a stop, as LinuxCNC's enable pin forces its output low: the line
// goes to its safe level in that very step and stays there while the enable is off. Stopped
// (enable off, configure, deactivate, error) it sits at its safe level and the count restarts, so
// the first edge after the enable comes back comes `divisor` steps later: the level is a pure
// function of the enabled steps since the last stop.
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

  // One write() cycle while active; returns the level to drive. `enabled` is the pump's enable on
  // this cycle (the gpiod driver: every output named in the channel's enabled_by written on).
  bool step(bool enabled) noexcept {
    if (!enabled) return stop();
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
