// hsad's start-up checks that need no device, run by the start and by `hsad --check-config` alike,
// so that whatever the start would refuse before it opens a device, the check refuses with the same
// words: each axis's signals bound to the channels its drivers' settings declare (Driver::plan),
// of the right kinds and with sane limits, and each axis's loop built from its parameters (its
// control law, the signals the law needs).
#pragma once

#include <vector>

#include "daemon/config/daemon_config.hpp"
#include "daemon/hsad/driver_set.hpp"

namespace hsa::daemon {

// Throws the start's refusal (io::BindingError, std::invalid_argument) for the first axis that has
// one; returns when every axis would start.
void check_axes(const DaemonConfig& config, const std::vector<PlannedDriver>& drivers);

}  // namespace hsa::daemon
