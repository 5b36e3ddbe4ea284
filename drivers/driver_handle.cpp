#include "drivers/driver_handle.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <thread>
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
  const DriverState s = state();
  // A failed driver's outputs go safe before on_error releases it (on_deactivate does it for the
  // others); a recovery that had started releasing it has already done so.
  if (s == DriverState::error && recovery_ == RecoveryStep::release) driver_->make_safe();
  if (s == DriverState::active) (void)driver_->on_deactivate();
  if (s == DriverState::active || s == DriverState::inactive) (void)driver_->on_cleanup();
  if (s == DriverState::error) {
    // Release what the driver still holds, from where a recovery (if any) left it.
    if (recovery_ == RecoveryStep::release) (void)driver_->on_error();
    if (recovery_ == RecoveryStep::activate) (void)driver_->on_cleanup();
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

Result DriverHandle::check_same_channels(std::span<const ChannelInfo> declared) const {
  const auto describe = [](const ChannelInfo& c) {
    return "'" + c.name + "' (" + std::string(to_string(c.kind)) + ", " + c.unit + ")";
  };
  if (declared.size() != channels_.size()) {
    return Result::failure(context() + ": declares " + std::to_string(declared.size()) +
                           " channels after recovery, " + std::to_string(channels_.size()) +
                           " before; the signals bound to them cannot follow");
  }
  for (std::size_t i = 0; i < declared.size(); ++i) {
    const ChannelInfo& now = declared[i];
    const ChannelInfo& was = channels_[i];
    if (now.name != was.name || now.kind != was.kind || now.unit != was.unit) {
      return Result::failure(context() + ": channel " + std::to_string(i) + " is " + describe(now) +
                             " after recovery, " + describe(was) +
                             " before; the signals bound to it cannot follow");
    }
  }
  return Result::success();
}

Result DriverHandle::recover(const toml::table& settings) {
  if (state() != DriverState::error) return transition_error("recover");
  // Until the final store the state stays `error`: the RT thread skips the driver and the slots
  // and channels_ are left alone, so the steps below are the only calls into the driver.
  if (recovery_ == RecoveryStep::release) {
    // Keep the RT thread's make_safe out of the driver from here until it is handed back, and
    // wait for a call in progress (it is bounded and short).
    releasing_.store(true, std::memory_order_seq_cst);
    while (make_safe_busy_.load(std::memory_order_seq_cst)) std::this_thread::yield();
    if (Result r = driver_->on_error(); !r) {
      state_.store(DriverState::finalized, std::memory_order_release);
      return Result::failure(context() + ": recovery failed, driver finalized: " + r.message());
    }
    recovery_ = RecoveryStep::configure;
  }
  if (recovery_ == RecoveryStep::configure) {
    if (Result r = driver_->on_configure(settings); !r) {
      return Result::failure(context() + ": recovery: " + r.message());
    }
    if (Result same = check_same_channels(driver_->channels()); !same) {
      (void)driver_->on_cleanup();  // unconfigured again: a later recover() configures anew
      return same;
    }
    recovery_ = RecoveryStep::activate;
  }
  if (failed_in_ == DriverState::active) {
    if (Result r = driver_->on_activate(); !r) {
      return Result::failure(context() + ": recovery: " + r.message());
    }
  }
  recovery_ = RecoveryStep::release;
  releasing_.store(false, std::memory_order_seq_cst);
  state_.store(failed_in_, std::memory_order_release);  // hands the driver back to the RT thread
  return Result::success();
}

void DriverHandle::fail(DriverState was, const char* what) noexcept {
  failed_in_ = was;
  // Bounded copies into a fixed buffer: no allocation on the RT thread.
  const std::string_view why = driver_->failure_reason();
  const std::size_t n = std::min(std::strlen(what), failure_.size() - 1);
  std::memcpy(failure_.data(), what, n);
  std::size_t end = n;
  if (!why.empty() && end + 2 < failure_.size() - 1) {
    std::memcpy(failure_.data() + end, ": ", 2);
    end += 2;
    const std::size_t m = std::min(why.size(), failure_.size() - 1 - end);
    std::memcpy(failure_.data() + end, why.data(), m);
    end += m;
  }
  failure_[end] = '\0';
  state_.store(DriverState::error, std::memory_order_release);
}

std::string DriverHandle::failure_reason() const {
  const DriverState s = state();
  if (s != DriverState::error && s != DriverState::finalized) return {};
  return failure_.data();
}

DriverHealth DriverHandle::health() const {
  const DriverState s = state();
  if (s != DriverState::inactive && s != DriverState::active && s != DriverState::error) return {};
  return driver_->health();
}

void DriverHandle::make_safe() noexcept {
  make_safe_busy_.store(true, std::memory_order_seq_cst);
  if (!releasing_.load(std::memory_order_seq_cst)) {
    const DriverState s = state();
    if (s == DriverState::inactive || s == DriverState::active || s == DriverState::error) driver_->make_safe();
  }
  make_safe_busy_.store(false, std::memory_order_release);
}

IoStatus DriverHandle::read(Timestamp t, Duration dt) noexcept {
  const DriverState s = state();
  if (s != DriverState::active && s != DriverState::inactive) return IoStatus::error;
  const IoStatus status = driver_->read(t, dt, slots_);
  if (status != IoStatus::ok) fail(s, status == IoStatus::write_error ? "write failed" : "read failed");
  return status;
}

IoStatus DriverHandle::write(Timestamp t, Duration dt) noexcept {
  if (state() != DriverState::active) return IoStatus::error;
  const IoStatus status = driver_->write(t, dt, slots_);
  if (status != IoStatus::ok) fail(DriverState::active, "write failed");
  return status;
}

std::optional<std::size_t> DriverHandle::find_channel(std::string_view channel) const {
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i].name == channel) return i;
  }
  return std::nullopt;
}

}  // namespace hsa::io
