// The framework's side of one driver instance: the driver object a plugin created, its lifecycle
// state, its declared channels and the buffer of channel slots the framework allocates for it.
//
// The handle enforces the ros2_control lifecycle (unconfigured → inactive → active, and back;
// a failed read or write moves it to `error` until recover()), so a driver is never called out
// of order. The slot buffer is allocated in configure() and not resized until cleanup(), so
// bound signals may hold pointers into it for as long as the driver stays configured.
//
// read/write run on the real-time thread; every other member runs on a normal thread and not
// concurrently with them (the daemon changes state at a cycle boundary). The state is atomic
// because the RT thread moves it to `error` while the supervisor thread watches it.
#pragma once

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
  error,      // a read or write failed; call recover()
  finalized,  // recovery failed; the driver is not used again
};

std::string_view to_string(DriverState state);

class DriverHandle {
 public:
  // Creates a driver from `plugin`; `name` is the instance's name in the configuration (e.g.
  // "rig"), used in every message. Throws PluginError{create_failed} when create() fails.
  DriverHandle(std::string name, std::shared_ptr<const Plugin> plugin);
  ~DriverHandle();  // deactivates and cleans up, so outputs end in their safe value
  DriverHandle(DriverHandle&&) = delete;  // bound signals point into the slots
  DriverHandle& operator=(DriverHandle&&) = delete;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const Plugin& plugin() const { return *plugin_; }
  [[nodiscard]] DriverState state() const { return state_.load(std::memory_order_acquire); }

  Result configure(const toml::table& settings);
  Result activate();
  Result deactivate();
  Result cleanup();
  // From `error`: runs on_error; success → unconfigured (configure again), failure → finalized.
  Result recover();

  // Real-time. read runs when inactive or active, write only when active; otherwise, or when the
  // driver reports an error, they return IoStatus::error (and the driver's error moves the state
  // to `error`).
  IoStatus read(Timestamp t, Duration dt) noexcept;
  IoStatus write(Timestamp t, Duration dt) noexcept;

  [[nodiscard]] std::span<const ChannelInfo> channels() const { return channels_; }
  [[nodiscard]] std::optional<std::size_t> find_channel(std::string_view channel) const;
  // Raw values, indexed like channels(). Signals bind to these; tests may inspect them.
  [[nodiscard]] std::span<ChannelSlot> slots() { return slots_; }
  [[nodiscard]] std::span<const ChannelSlot> slots() const { return slots_; }

 private:
  Result transition_error(std::string_view action) const;
  std::string context() const;  // "driver 'rig' (plugin sim)"

  std::shared_ptr<const Plugin> plugin_;  // declared first: outlives driver_
  std::unique_ptr<Driver, void (*)(Driver*)> driver_;
  std::string name_;
  std::atomic<DriverState> state_{DriverState::unconfigured};
  std::vector<ChannelInfo> channels_;
  std::vector<ChannelSlot> slots_;
};

}  // namespace hsa::io
