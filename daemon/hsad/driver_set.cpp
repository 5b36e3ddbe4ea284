#include "daemon/hsad/driver_set.hpp"

#include <stdexcept>

#include "drivers/plugin_loader.hpp"

namespace hsa::daemon {

DriverSet::DriverSet(const DaemonConfig& config) {
  if (config.drivers.size() > 64) throw std::invalid_argument("hsad: at most 64 driver instances");
  const io::PluginLoader loader(io::default_plugin_dirs());
  for (const DriverConfig& d : config.drivers) {
    drivers_.push_back(loader.load_driver(d.name, d.plugin, d.settings));
  }
}

DriverSet::~DriverSet() { deactivate_all(); }

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

}  // namespace hsa::daemon
