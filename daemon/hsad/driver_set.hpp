// The daemon's driver instances, loaded and configured from the configuration, and driven as a
// group by the RT cycle: every input read before the axes run, every output written after.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "daemon/config/daemon_config.hpp"
#include "drivers/driver_handle.hpp"

namespace hsa::daemon {

class DriverSet {
 public:
  // Loads each plugin and configures it with its settings; throws with the plugin's own message.
  explicit DriverSet(const DaemonConfig& config);
  ~DriverSet();  // deactivates and cleans up every driver (outputs to their safe values)

  void activate_all();    // throws naming the driver that refused
  void deactivate_all();  // best effort: every driver gets its chance

  // RT: read or write every driver; a driver that fails sets its bit in the returned mask.
  std::uint64_t read_all(io::Timestamp t, io::Duration dt) noexcept;
  std::uint64_t write_all(io::Timestamp t, io::Duration dt) noexcept;

  [[nodiscard]] std::vector<io::DriverHandle*> handles() const;
  // Bit mask of the drivers whose names are given (for an axis's driver-error fault).
  [[nodiscard]] std::uint64_t mask_of(const std::vector<std::string>& names) const;

 private:
  std::vector<std::unique_ptr<io::DriverHandle>> drivers_;
};

}  // namespace hsa::daemon
