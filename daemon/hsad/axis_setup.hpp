// From an axis's configuration to what its RT loop needs: the supervisor's parameters (limits
// turned into cycle counts at the base rate) and the signal bindings.
#pragma once

#include <string>
#include <vector>

#include "daemon/config/daemon_config.hpp"
#include "daemon/axis/axis_params.hpp"

namespace hsa::daemon {

[[nodiscard]] AxisParams axis_params(const AxisConfig& axis, const RealtimeConfig& realtime);
// The driver instances an axis reads or writes, for its driver-error fault.
[[nodiscard]] std::vector<std::string> drivers_of(const AxisConfig& axis);

}  // namespace hsa::daemon
