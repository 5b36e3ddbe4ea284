// The interface every I/O driver implements, with the lifecycle of ros2_control's hardware
// components.
//
//   on_configure  read the settings, open the bus, declare the channels; no commands yet
//   on_activate   power the outputs
//   read / write  every cycle, on the real-time thread
//   make_safe     on the real-time thread, whenever the daemon wants the outputs safe now: in
//                 the cycle a read or write failed (the driver is then in `error` and gets no
//                 more read or write) and on every way out of running. It must work on a driver
//                 that just failed, which is why it is separate from on_deactivate (a lifecycle
//                 step, on a normal thread, that may wait).
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
#include <string_view>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/driver_health.hpp"
#include "drivers/driver_plan.hpp"
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

  // Checks `settings` as on_configure would, without opening a bus, a socket or a line and
  // without keeping anything: `hsad --check-config` runs it on every driver of a configuration, so
  // a typo in a plugin's settings is found before anything is started. Any thread.
  [[nodiscard]] virtual Result check_settings(const toml::table& settings) const = 0;

  // Checks `settings` as check_settings does and states what they make the driver open and
  // declare (driver_plan.hpp), again without opening or keeping anything. Any thread.
  [[nodiscard]] virtual Result plan(const toml::table& settings, DriverPlan& plan) const = 0;

  virtual Result on_activate() { return Result::success(); }
  virtual Result on_deactivate() { return Result::success(); }
  virtual Result on_cleanup() { return Result::success(); }
  virtual Result on_error() { return Result::success(); }

  // `t` is the start of the current cycle, `dt` the time since the previous one. read fills the
  // input slots; write sends the output slots.
  virtual IoStatus read(Timestamp t, Duration dt, std::span<ChannelSlot> slots) noexcept = 0;
  virtual IoStatus write(Timestamp t, Duration dt, std::span<const ChannelSlot> slots) noexcept = 0;

  // Real-time, like read and write: puts every output at its safe value, at once or through the
  // driver's own I/O thread at its next chance, and keeps it there until the driver is activated
  // again (or configured again, after on_error). Bounded; allocates, locks, logs and blocks
  // nothing. Called while configured, also after a read or write failed; a no-op otherwise.
  virtual void make_safe() noexcept = 0;

  // Real-time: why the last read or write failed (IoStatus::error or write_error), in the device's own terms
  // (a Modbus exception code and register block, a CAN send's errno text); empty when the driver
  // has nothing to add. The text lives in the driver and stays valid until its next read or write.
  [[nodiscard]] virtual std::string_view failure_reason() const noexcept { return {}; }

  // Normal thread, while configured (also during read and write on the RT thread): the link's
  // state, last error and counters (driver_health.hpp). Allocates; never on the RT thread.
  [[nodiscard]] virtual DriverHealth health() const { return {}; }

 protected:
  Driver() = default;
  Driver(const Driver&) = default;
  Driver& operator=(const Driver&) = default;
};

}  // namespace hsa::io
