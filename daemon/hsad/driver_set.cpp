#include "daemon/hsad/driver_set.hpp"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/plugin_loader.hpp"

namespace hsa::daemon {

namespace {

// "<file>:<line>:<column>: drivers 'rig' (plugin sim): <key>: ..." when the plugin's message is
// located in the configuration file (its settings reader names the place first), and
// "<file>: drivers 'rig' (plugin sim): <message>" when it is not (a plugin that cannot be loaded).
std::string driver_failure(const DaemonConfig& config, const DriverConfig& d, const std::string& message) {
  const std::string who = "drivers '" + d.name + "' (plugin " + d.plugin + "): ";
  const std::string file = config.source + ":";
  std::size_t place_end = 0;
  if (message.starts_with(file)) {
    // file:line:column: — two numbers, each followed by a colon, then a space.
    std::size_t i = file.size();
    for (int field = 0; field < 2 && i < message.size(); ++field) {
      const std::size_t digits = i;
      while (i < message.size() && message[i] >= '0' && message[i] <= '9') ++i;
      if (i == digits || i >= message.size() || message[i] != ':') break;
      ++i;
      if (field == 1 && i < message.size() && message[i] == ' ') place_end = i + 1;
    }
  }
  if (place_end == 0) return file + " " + who + message;
  return message.substr(0, place_end) + who + message.substr(place_end);
}

}  // namespace

DriverPlans plan_drivers(const DaemonConfig& config) {
  const io::PluginLoader loader(io::default_plugin_dirs());
  DriverPlans plans;
  for (const DriverConfig& d : config.drivers) {
    try {
      const std::shared_ptr<const io::Plugin> plugin = loader.load(d.plugin);
      const hsa_plugin_descriptor& descriptor = plugin->descriptor();
      const std::unique_ptr<io::Driver, void (*)(io::Driver*)> driver(descriptor.create(), descriptor.destroy);
      if (!driver) {
        plans.refused.push_back(driver_failure(config, d, "the plugin could not create a driver"));
        continue;
      }
      PlannedDriver planned{d.name, descriptor.name, {}};
      if (const io::Result r = driver->plan(d.settings, planned.plan); !r) {
        plans.refused.push_back(driver_failure(config, d, r.message()));
        continue;
      }
      plans.drivers.push_back(std::move(planned));
    } catch (const std::exception& e) {
      plans.refused.push_back(driver_failure(config, d, e.what()));
    }
  }
  return plans;
}

DriverSet::DriverSet(const DaemonConfig& config) {
  // load_config refuses more, naming the file and line; a configuration built in code is checked here.
  static_assert(kMaxDriverInstances <= 64, "a driver's failure is one bit of a std::uint64_t mask");
  if (config.drivers.size() > kMaxDriverInstances) {
    throw std::invalid_argument("hsad: at most " + std::to_string(kMaxDriverInstances) + " driver instances");
  }
  const io::PluginLoader loader(io::default_plugin_dirs());
  for (const DriverConfig& d : config.drivers) {
    drivers_.push_back(loader.load_driver(d.name, d.plugin, d.settings));
    settings_.push_back(d.settings);
  }
}

DriverSet::~DriverSet() {
  make_safe(~std::uint64_t{0});
  deactivate_all();
}

void DriverSet::make_safe(std::uint64_t mask) noexcept {
  for (std::size_t i = 0; i < drivers_.size(); ++i)
    if ((mask & (std::uint64_t{1} << i)) != 0) drivers_[i]->make_safe();
}

std::string DriverSet::failures_of(std::uint64_t mask) const {
  std::string text;
  for (std::size_t i = 0; i < drivers_.size(); ++i) {
    if ((out_of_cycle(mask) & (std::uint64_t{1} << i)) == 0) continue;
    text += (text.empty() ? "'" : "; '") + drivers_[i]->name() + "': " + drivers_[i]->failure_reason();
  }
  return text;
}

void DriverSet::activate_all() {
  for (auto& d : drivers_) {
    const io::Result r = d->activate();
    if (!r) throw std::runtime_error("hsad: cannot activate driver '" + d->name() + "': " + r.message());
  }
}

void DriverSet::deactivate_all() {
  for (auto& d : drivers_) {
    if (d->state() == io::DriverState::active) (void)d->deactivate();
  }
}

std::uint64_t DriverSet::read_all(io::Timestamp t, io::Duration dt) noexcept {
  std::uint64_t failed = 0;
  for (std::size_t i = 0; i < drivers_.size(); ++i)
    if (drivers_[i]->read(t, dt) != io::IoStatus::ok) failed |= std::uint64_t{1} << i;
  return failed;
}

std::uint64_t DriverSet::write_all(io::Timestamp t, io::Duration dt) noexcept {
  std::uint64_t failed = 0;
  for (std::size_t i = 0; i < drivers_.size(); ++i)
    if (drivers_[i]->write(t, dt) != io::IoStatus::ok) failed |= std::uint64_t{1} << i;
  return failed;
}

io::Result DriverSet::recover(std::uint64_t mask) {
  std::string failures;
  for (std::size_t i = 0; i < drivers_.size(); ++i) {
    if ((mask & (std::uint64_t{1} << i)) == 0) continue;
    const io::DriverState state = drivers_[i]->state();
    if (state == io::DriverState::finalized) {
      failures += (failures.empty() ? "" : "; ") + std::string("driver '") + drivers_[i]->name() +
                  "' is finalized (an earlier recovery failed): restart hsad";
    } else if (state == io::DriverState::error) {
      if (const io::Result r = drivers_[i]->recover(settings_[i]); !r) {
        failures += (failures.empty() ? "" : "; ") + r.message();
      }
    }
  }
  return failures.empty() ? io::Result::success() : io::Result::failure(failures);
}

std::uint64_t DriverSet::out_of_cycle(std::uint64_t mask) const {
  std::uint64_t out = 0;
  for (std::size_t i = 0; i < drivers_.size(); ++i) {
    const io::DriverState s = drivers_[i]->state();
    if (s == io::DriverState::error || s == io::DriverState::finalized) out |= std::uint64_t{1} << i;
  }
  return out & mask;
}

std::vector<io::DriverHandle*> DriverSet::handles() const {
  std::vector<io::DriverHandle*> out;
  for (const auto& d : drivers_) out.push_back(d.get());
  return out;
}

std::uint64_t DriverSet::mask_of(const std::vector<std::string>& names) const {
  std::uint64_t mask = 0;
  for (std::size_t i = 0; i < drivers_.size(); ++i)
    for (const auto& n : names)
      if (drivers_[i]->name() == n) mask |= std::uint64_t{1} << i;
  return mask;
}

std::string DriverSet::names_of(std::uint64_t mask) const {
  std::string names;
  for (std::size_t i = 0; i < drivers_.size(); ++i) {
    if ((mask & (std::uint64_t{1} << i)) == 0) continue;
    names += (names.empty() ? "'" : ", '") + drivers_[i]->name() + "'";
  }
  return names;
}

}  // namespace hsa::daemon
