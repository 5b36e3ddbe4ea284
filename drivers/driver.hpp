// The interface every I/O driver implements, with the lifecycle of ros2_control's hardware
// components.
//
//   on_configure  read the settings, open the bus, declare the channels; no commands yet
//   on_activate   power the outputs
//   read / write  every cycle, on the real-time thread
//   on_deactivate put the outputs in their safe value
//   on_cleanup    close the bus; the driver may be configured again
//   on_error      where a failed read or write lands; runs on a normal thread, never the RT one.
//                 Release what on_configure acquired and try to bring the bus back: on success
//                 the driver is unconfigured and may be configured again, on failure it is
//                 finalized and never used again.
//
// Key decision: the driver does not own the storage of its channel values. The framework
// allocates one ChannelSlot per declared channel when the driver is configured and passes that
// buffer to every read and write, indexed like channels(). So a driver needs no pointers into
// the framework, and the framework can bind signals to slots before the first cycle.
//
// read and write are noexcept and must not allocate, lock, log or block beyond the driver's own
// bounded I/O. Lifecycle steps run on a normal thread; they report failure through Result and
// do not throw across the plugin boundary.
#pragma once

#include <span>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/result.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io {

class Driver {
 public:
  virtual ~Driver() = default;

  // `settings` is the driver's own table from the daemon's configuration. A failure names the
  // offending key and what was expected.
  virtual Result on_configure(const toml::table& settings) = 0;

  // The channels, valid from a successful on_configure until on_cleanup. The set may depend on
  // the settings (a rig with a servo-valve has no spool LVDT).
  [[nodiscard]] virtual std::span<const ChannelInfo> channels() const = 0;

  virtual Result on_activate() { return Result::success(); }
  virtual Result on_deactivate() { return Result::success(); }
  virtual Result on_cleanup() { return Result::success(); }
  virtual Result on_error() { return Result::success(); }

  // `t` is the start of the current cycle, `dt` the time since the previous one. read fills the
  // input slots; write sends the output slots.
  virtual IoStatus read(Timestamp t, Duration dt, std::span<ChannelSlot> slots) noexcept = 0;
  virtual IoStatus write(Timestamp t, Duration dt, std::span<const ChannelSlot> slots) noexcept = 0;

 protected:
  Driver() = default;
  Driver(const Driver&) = default;
  Driver& operator=(const Driver&) = default;
};

}  // namespace hsa::io
