// The daemon's driver instances, loaded and configured from the configuration, and driven as a
// group by the RT cycle: every input read before the axes run, every output written after.
//
// A driver whose read or write fails stays in its error state, and the RT cycle reports it in
// every cycle's mask (its bit set) without calling it. recover() brings it back, on a normal
// thread, with the settings it was configured with at start-up (DriverHandle::recover): the RT
// thread never runs a lifecycle step.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "daemon/config/daemon_config.hpp"
#include "drivers/driver_handle.hpp"
#include "drivers/driver_plan.hpp"
#include "drivers/signal_binding.hpp"

namespace hsa::daemon {

// One driver instance as its settings describe it (Driver::plan): what it would open and declare.
struct PlannedDriver {
  std::string name;    // the instance's name in the configuration
  std::string plugin;  // the plugin's name
  io::DriverPlan plan;
  [[nodiscard]] io::DeclaredDriver declared() const { return {name, plugin, plan.channels}; }
};

struct DriverPlans {
  std::vector<PlannedDriver> drivers;  // those whose plugin stated a plan, in configuration order
  // One line per driver whose plugin cannot be loaded or refuses its settings, naming the file,
  // the driver and the plugin; empty when all passed.
  std::vector<std::string> refused;
};

// Loads each driver's plugin and asks it for its plan, which opens no device. hsad does it before
// it locks (the plans name the devices) and `hsad --check-config` before it checks the bindings.
[[nodiscard]] DriverPlans plan_drivers(const DaemonConfig& config);

class DriverSet {
 public:
  // Loads each plugin and configures it with its settings; throws with the plugin's own message.
  explicit DriverSet(const DaemonConfig& config);
  // make_safe on every driver, then deactivates and cleans up each (outputs to their safe values):
  // the last word on every way out, an exception included (the RT thread has stopped by then).
  ~DriverSet();

  void activate_all();    // throws naming the driver that refused
  void deactivate_all();  // best effort: every driver gets its chance

  // RT: read or write every driver; a driver that fails sets its bit in the returned mask.
  std::uint64_t read_all(io::Timestamp t, io::Duration dt) noexcept;
  std::uint64_t write_all(io::Timestamp t, io::Duration dt) noexcept;
  // RT: make_safe on every driver of `mask` (DriverHandle::make_safe: also those in error).
  void make_safe(std::uint64_t mask) noexcept;

  // Normal thread, while the RT thread runs: recovers every driver of `mask` that is in its error
  // state. Each is tried; the result names every driver that could not be recovered (the others
  // are back in the cycle).
  io::Result recover(std::uint64_t mask);
  // The drivers of `mask` that the RT cycle is not running (error or finalized), as a mask.
  [[nodiscard]] std::uint64_t out_of_cycle(std::uint64_t mask) const;

  [[nodiscard]] std::vector<io::DriverHandle*> handles() const;
  // Bit mask of the drivers whose names are given (for an axis's driver-error fault).
  [[nodiscard]] std::uint64_t mask_of(const std::vector<std::string>& names) const;
  // The names of the drivers of `mask`, quoted and comma-separated: "'rig', 'aux'".
  [[nodiscard]] std::string names_of(std::uint64_t mask) const;
  // Normal thread: "'rig': write failed: Modbus exception 3 (...) ...", for every driver of `mask`
  // that is out of the cycle, joined by "; ".
  [[nodiscard]] std::string failures_of(std::uint64_t mask) const;

 private:
  std::vector<std::unique_ptr<io::DriverHandle>> drivers_;
  std::vector<toml::table> settings_;  // drivers_[i]'s settings from the configuration
};

}  // namespace hsa::daemon
