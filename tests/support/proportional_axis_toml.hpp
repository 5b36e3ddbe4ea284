#pragma once

// The proportional-valve axis that hsad's configuration tests write (one `sim` rig, the cascade
// through the valve loop, the paper's PI gains), with its [axes.valve_law] table left to the
// caller: the tests that read a valve law through the daemon's own configuration parser.

#include <string>
#include <string_view>

namespace hsa::test {

inline std::string proportional_axis_toml(std::string_view valve_law_table) {
  constexpr std::string_view kHead = R"([[drivers]]
name = "rig"
plugin = "sim"
[drivers.settings]
valve = "proportional"

[[axes]]
name = "x"
drive = "proportional"
[axes.signals.position]
driver = "rig"
channel = "encoder"
[axes.signals.pressure_a]
driver = "rig"
channel = "pressure_a"
[axes.signals.pressure_b]
driver = "rig"
channel = "pressure_b"
[axes.signals.spool]
driver = "rig"
channel = "spool_lvdt"
[axes.signals.valve_command]
driver = "rig"
channel = "current_ref"
[axes.signals.valve_enable]
driver = "rig"
channel = "valve_enable"
[axes.pi]
kp = 85.0
ki = 460.0
max_speed_m_s = 0.2
)";
  constexpr std::string_view kTail = R"(
[axes.limits]
soft_min_m = 0.01
soft_max_m = 0.29
[axes.safety]
max_pressure_pa = 30e5
max_following_error_m = 0.02
encoder_jump_m = 0.005
)";
  return std::string(kHead) + std::string(valve_law_table) + std::string(kTail);
}

}  // namespace hsa::test
