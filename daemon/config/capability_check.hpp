// An axis's configured motion bounds against what its plant can follow: the capability of the
// plant-set file the axis names in [axes.pi] `plants` (`hsa-analyze identify --set`; docs/plant-set.md,
// control/identification/axis_capability.hpp), per direction its speed_limit_m_s and
// acceleration_limit_m_s2, a margin below what the valve gives at the worst identified load.
//
// - pi.max_speed_m_s bounds every setpoint the axis follows, streamed or a move's, either way: it
//   must be within the smaller of the two directions' speed limits, or the configuration is
//   refused naming the key, its value, the direction and figure it exceeds and the file.
// - limits.max_accel_m_s2 likewise, against the smaller acceleration limit. Unset, it stays what it
//   is without a plant set (max_speed_m_s reached in safety_defaults::kDefaultRampS), lowered to
//   that smaller limit only where the limit is less: the capability is the most a profile may ask
//   of the plant, with the margin for the loop's corrections, not a pace to move at (the moves'
//   0.2 mm overshoot was measured at the derived pace). The jerk, unset, follows from it as before
//   (reached in kDefaultJerkRampS).
// The capability itself goes to the axis (AxisConfig::capability), which bounds each move by the
// direction it travels (daemon/supervisor/axis_supervisor.hpp).
#pragma once

#include "daemon/config/axis_config.hpp"
#include "daemon/config/law_settings_reader.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

// `axis` is the [[axes]] table `a` was read from. Throws io::ConfigError at the key that is over.
void apply_capability(const io::TableReader& axis, const LoadedPlantSet& plants, AxisConfig& a);

}  // namespace hsa::daemon
