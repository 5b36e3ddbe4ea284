// The bounds of the configuration's numbers: what hsad accepts for a hydraulic servo-actuator of
// the lab scale this project targets, stated once. A value outside them is refused with the file,
// line and key (load_config.cpp), so a typo of a few orders of magnitude (kp = 85e3, a pressure
// in bar where Pa is meant, a timeout in ms where s is meant) never reaches the loops. docs/operation.md's
// "Configuration bounds" table lists the same numbers.
#pragma once

namespace hsa::daemon::bounds {

// The control laws bound their own tables: control/laws/pi_cascade_law.hpp ([axes.pi]) and
// control/laws/proportional_cascade/ ([axes.valve_law]).

// Supervision thresholds.
inline constexpr double kMaxPressurePa = 70e6;     // 700 bar: above any industrial hydraulic supply
inline constexpr double kMaxDistanceM = 1.0;       // following error, encoder jump margin
inline constexpr double kMaxTimeoutS = 10.0;       // saturation time, setpoint timeout, staleness

// The safe valve command must close the valve: within this band around closed, by default
// (safe_command_band; at most kMaxSafeCommandBand). Closed is opening 0 for a servo-valve; for a
// proportional valve the null current (valve_law.bias_current_a), or 0 A, de-energized, where the
// spring parks the spool in its fail-safe position. The band is a fraction of the range: of the
// opening for a servo-valve, of max_current_a for a proportional valve.
inline constexpr double kDefaultSafeCommandBand = 0.02;
inline constexpr double kMaxSafeCommandBand = 0.1;

}  // namespace hsa::daemon::bounds
