#include "drivers/driver_handle.hpp"

#include <algorithm>
#include <utility>

#include "drivers/plugin_error.hpp"

namespace hsa::io {

std::string_view to_string(DriverState state) {
  switch (state) {
    case DriverState::unconfigured: return "unconfigured";
    case DriverState::inactive: return "inactive";
    case DriverState::active: return "active";
    case DriverState::error: return "error";
    case DriverState::finalized: return "finalized";
  }
  return "unknown state";
}

namespace {

Driver* create_driver(const Plugin& plugin, const std::string& name) {
  Driver* driver = plugin.descriptor().create();
  if (driver == nullptr) {
    throw PluginError(PluginErrorKind::create_failed, plugin.name(),
                      "driver '" + name + "' (plugin " + plugin.name() + ", " +
                          plugin.path().string() + "): create() returned no driver");
  }
  return driver;
}

}  // namespace

DriverHandle::DriverHandle(std::string name, std::shared_ptr<const Plugin> plugin)
    : plugin_(std::move(plugin)),
      driver_(create_driver(*plugin_, name), plugin_->descriptor().destroy),
      name_(std::move(name)) {}

DriverHandle::~DriverHandle() {
  // Results are dropped: there is no one left to tell, and each step is still worth trying.
  if (state() == DriverState::active) (void)driver_->on_deactivate();
  if (state() == DriverState::active || state() == DriverState::inactive) {
    (void)driver_->on_cleanup();
  }
}

std::string DriverHandle::context() const {
  return "driver '" + name_ + "' (plugin " + plugin_->name() + ")";
}

Result DriverHandle::transition_error(std::string_view action) const {
  return Result::failure(context() + ": cannot " + std::string(action) + " while " +
                         std::string(to_string(state())));
}

Result DriverHandle::configure(const toml::table& settings) {
  if (state() != DriverState::unconfigured) return transition_error("configure");
  if (Result r = driver_->on_configure(settings); !r) {
    return Result::failure(context() + ": " + r.message());
  }
  const auto declared = driver_->channels();
  std::vector<ChannelInfo> channels(declared.begin(), declared.end());
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    const bool duplicate = std::any_of(channels.begin(), it, [&](const ChannelInfo& c) {
      return c.name == it->name;
    });
    if (it->name.empty() || duplicate) {
      (void)driver_->on_cleanup();
      return Result::failure(context() + ": declares " +
                             (it->name.empty() ? "a channel without a name"
                                               : "channel '" + it->name + "' twice"));
    }
  }
  channels_ = std::move(channels);
  slots_.assign(channels_.size(), ChannelSlot{});
  state_.store(DriverState::inactive, std::memory_order_release);
  return Result::success();
}

Result DriverHandle::activate() {
  if (state() != DriverState::inactive) return transition_error("activate");
  if (Result r = driver_->on_activate(); !r) return Result::failure(context() + ": " + r.message());
  state_.store(DriverState::active, std::memory_order_release);
  return Result::success();
}

Result DriverHandle::deactivate() {
  if (state() != DriverState::active) return transition_error("deactivate");
  // Inactive even when on_deactivate fails: write() stops either way, and the failure is reported.
  state_.store(DriverState::inactive, std::memory_order_release);
  if (Result r = driver_->on_deactivate(); !r) {
    return Result::failure(context() + ": " + r.message());
  }
  return Result::success();
}

Result DriverHandle::cleanup() {
  if (state() != DriverState::inactive) return transition_error("clean up");
  state_.store(DriverState::unconfigured, std::memory_order_release);
  channels_.clear();
  slots_.clear();
  if (Result r = driver_->on_cleanup(); !r) return Result::failure(context() + ": " + r.message());
  return Result::success();
}

Result DriverHandle::recover() {
  if (state() != DriverState::error) return transition_error("recover");
  Result r = driver_->on_error();
  channels_.clear();
  slots_.clear();
  if (!r) {
    state_.store(DriverState::finalized, std::memory_order_release);
    return Result::failure(context() + ": recovery failed, driver finalized: " + r.message());
  }
  state_.store(DriverState::unconfigured, std::memory_order_release);
  return Result::success();
}

IoStatus DriverHandle::read(Timestamp t, Duration dt) noexcept {
  const DriverState s = state();
  if (s != DriverState::active && s != DriverState::inactive) return IoStatus::error;
  const IoStatus status = driver_->read(t, dt, slots_);
  if (status != IoStatus::ok) state_.store(DriverState::error, std::memory_order_release);
  return status;
}

IoStatus DriverHandle::write(Timestamp t, Duration dt) noexcept {
  if (state() != DriverState::active) return IoStatus::error;
  const IoStatus status = driver_->write(t, dt, slots_);
  if (status != IoStatus::ok) state_.store(DriverState::error, std::memory_order_release);
  return status;
}

std::optional<std::size_t> DriverHandle::find_channel(std::string_view channel) const {
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].name == channel) return i;
  }
  return std::nullopt;
}

}  // namespace hsa::io
