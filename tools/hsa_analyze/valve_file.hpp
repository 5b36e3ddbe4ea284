// The valve `hsa-analyze experiment valve --valve FILE` (and valve-excite) runs on, when it is not
// the paper's: a TOML file with one table, [rig.proportional_valve], whose keys are the sim
// plugin's (docs/simulator.md, "A rig other than the paper's"), as a hsad configuration writes them
// under [drivers.settings.rig.proportional_valve]. The plugin's own reader (drivers/sim/
// rig_settings.hpp) reads it, so the bounds and the consistency checks (stops in order, a dead
// band that leaves the current enough to open the valve fully) are the daemon's; a key left out
// keeps the paper's value. Anything else in the file (another [rig] group, a top-level key) is
// refused rather than ignored: the valve experiments run the valve alone.
#pragma once

#include <string>
#include <string_view>

#include "sim/proportional_valve.hpp"

namespace hsa::analyze {

// Throws io::ConfigError "<file>:<line>:<column>: <key>: expected …, got …" for a syntax error,
// an unknown key or table, a value out of its bounds or an inconsistent valve; "cannot open" for
// a file that cannot be read.
[[nodiscard]] sim::ProportionalValveParameters parse_valve_file(std::string_view text, std::string_view source_name);
[[nodiscard]] sim::ProportionalValveParameters load_valve_file(const std::string& path);

}  // namespace hsa::analyze
