// The framework's side of one driver instance: the driver object a plugin created, its lifecycle
// state, its declared channels and the buffer of channel slots the framework allocates for it.
//
// The handle enforces the ros2_control lifecycle (unconfigured → inactive → active, and back;
// a failed read or write moves it to `error` until recover()), so a driver is never called out
// of order. The slot buffer is allocated in configure() and not resized until cleanup(), so
// bound signals may hold pointers into it for as long as the driver stays configured.
//
// read/write run on the real-time thread; every other member runs on a normal thread and not
// concurrently with them (the daemon changes state at a cycle boundary), except recover(): it
// runs while the RT thread keeps cycling. The state is atomic because the RT thread moves it to
// `error` while a normal thread watches it, and because it is the flag that hands a recovered
// driver back to the RT thread.
//
// Recovery, and why it is safe with the RT thread running: in `error`, read and write return at
// once without touching the driver or the slots. recover() walks the driver through on_error,
// on_configure (same settings) and on_activate while the state stays `error`, so the RT thread
// never sees a half-recovered driver; it then stores the state the driver failed in with release
// order, and the RT thread's acquire load at its next read sees a driver ready to run. The slot
// buffer is kept as it is (the driver must declare exactly the channels it had), so every signal
// bound at start-up stays valid, and nothing is written to it while the RT thread uses it.
//
// make_safe is the exception to "in `error`, nothing reaches the driver": a driver that failed
// must still get its outputs safe, from the RT thread, in the same cycle. So make_safe reaches the
// driver in `inactive`, `active` and `error`, until recover() starts on_error: recover() first
// raises `releasing_` and waits for a make_safe in progress to return (both flags seq_cst, so
// either the RT thread sees `releasing_` or recover() sees it busy), and only then releases the
// driver. From there until the recovery hands the driver back, make_safe is a no-op.
//
// The reason of a failure: fail() copies the driver's failure_reason() into a fixed buffer before
// it stores `error` (release). Only recover() moves the state out of `error`, so the normal thread
// that calls recover() may read the buffer whenever it sees `error` or `finalized`.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/driver.hpp"
#include "drivers/plugin.hpp"
#include "drivers/result.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io {

enum class DriverState : unsigned char {
  unconfigured,
  inactive,   // configured: channels declared, slots allocated; inputs may be read
  active,     // outputs powered; read and write every cycle
  error,      // a read or write failed: read/write no longer reach the driver; call recover()
  finalized,  // on_error failed; the driver is not used again
};

std::string_view to_string(DriverState state);

class DriverHandle {
 public:
  // Creates a driver from `plugin`; `name` is the instance's name in the configuration (e.g.
  // "rig"), used in every message. Throws PluginError{create_failed} when create() fails.
  DriverHandle(std::string name, std::shared_ptr<const Plugin> plugin);
  // Deactivates and cleans up, so outputs end in their safe value; a driver in `error` gets its
  // on_error (or on_cleanup, when a recovery stopped after configuring it).
  ~DriverHandle();
  DriverHandle(DriverHandle&&) = delete;  // bound signals point into the slots
  DriverHandle& operator=(DriverHandle&&) = delete;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const Plugin& plugin() const { return *plugin_; }
  [[nodiscard]] DriverState state() const { return state_.load(std::memory_order_acquire); }

  Result configure(const toml::table& settings);
  Result activate();
  Result deactivate();
  Result cleanup();
  // From `error`, on a normal thread while the RT thread may keep calling read/write: on_error,
  // then on_configure with `settings` and, when the driver failed while active, on_activate. The
  // state goes back to what it was when the driver failed only once every step succeeded and the
  // driver declared the same channels (name, kind, unit, order) as before, so the slots and the
  // signals bound to them are unchanged. On failure the state stays `error` and a later call
  // resumes at the step that failed; when on_error itself fails the driver is `finalized`.
  Result recover(const toml::table& settings);

  // Real-time. read runs when inactive or active, write only when active; otherwise, or when the
  // driver reports an error, they return IoStatus::error (and the driver's error moves the state
  // to `error`).
  IoStatus read(Timestamp t, Duration dt) noexcept;
  IoStatus write(Timestamp t, Duration dt) noexcept;
  // Real-time: the driver's make_safe, when it is inactive, active or in `error` (unless a
  // recovery is releasing it); otherwise nothing. Never changes the state.
  void make_safe() noexcept;

  // Normal thread, meaningful in `error` or `finalized`: "read failed" or "write failed", then
  // the driver's own reason when it gave one ("write failed: Modbus exception 3 ...").
  [[nodiscard]] std::string failure_reason() const;
  // Normal thread: the driver's health (driver_health.hpp) while configured (inactive, active or
  // in error); no link to speak of otherwise.
  [[nodiscard]] DriverHealth health() const;

  [[nodiscard]] std::span<const ChannelInfo> channels() const { return channels_; }
  [[nodiscard]] std::optional<std::size_t> find_channel(std::string_view channel) const;
  // Raw values, indexed like channels(). Signals bind to these; tests may inspect them.
  [[nodiscard]] std::span<ChannelSlot> slots() { return slots_; }
  [[nodiscard]] std::span<const ChannelSlot> slots() const { return slots_; }

 private:
  // Where recover() resumes: the driver's own lifecycle position while the handle shows `error`.
  enum class RecoveryStep : unsigned char { release, configure, activate };

  Result transition_error(std::string_view action) const;
  std::string context() const;  // "driver 'rig' (plugin sim)"
  // Success when `declared` equals channels_; else a failure naming the first difference.
  Result check_same_channels(std::span<const ChannelInfo> declared) const;
  // RT: the driver failed while in `was`; read and write stop reaching it.
  void fail(DriverState was, const char* what) noexcept;

  std::shared_ptr<const Plugin> plugin_;  // declared first: outlives driver_
  std::unique_ptr<Driver, void (*)(Driver*)> driver_;
  std::string name_;
  std::atomic<DriverState> state_{DriverState::unconfigured};
  // Written by the RT thread before it stores `error` (release), read by recover() after it
  // loaded `error` (acquire): the state to return to.
  DriverState failed_in_ = DriverState::active;
  RecoveryStep recovery_ = RecoveryStep::release;  // normal thread only
  std::vector<ChannelInfo> channels_;
  std::vector<ChannelSlot> slots_;
  std::array<char, 256> failure_{};       // RT writes before `error`; see the header comment
  std::atomic<bool> make_safe_busy_{false};  // RT: inside the driver's make_safe
  std::atomic<bool> releasing_{false};       // recover(): on_error started, keep make_safe out
};

}  // namespace hsa::io
