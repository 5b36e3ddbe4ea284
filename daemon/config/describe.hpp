// A one-screen, human-readable summary of a validated configuration, for hsad --check-config.
#pragma once

#include <string>

#include "daemon/config/daemon_config.hpp"

namespace hsa::daemon {

std::string describe(const DaemonConfig& config);

}  // namespace hsa::daemon
