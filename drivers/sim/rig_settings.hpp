// The simulated rig a sim plugin's settings describe: the plugin's one reader of sim::RigConfig,
// shared with `hsa-analyze calibration --config` so that the tool linearizes exactly the rig the
// daemon would run.
//
// Top-level keys: valve, load_kg, initial_position_m, seed, step_s. The physical parameters sit in
// an optional [rig] table, one sub-table per parameter group of sim::RigConfig, one key per
// parameter in SI units with the unit in its name:
//   [rig.cylinder]            geometry (stroke, bore, rod, dead length), gravity, dry friction,
//                             null leakage (sim/cylinder.hpp, sim/cylinder_geometry.hpp)
//   [rig.dynamics]            moving mass, viscous damping, bulk modulus, valve flow coefficient:
//                             unset, the paper's identified values at each working point
//                             (sim/identified_parameters.hpp)
//   [rig.supply]              supply pressure, pump flow (sim/hydraulic_supply.hpp)
//   [rig.servo_valve]         bandwidth, damping (sim/servo_valve.hpp)
//   [rig.proportional_valve]  sim/proportional_valve.hpp
//   [rig.sensors]             encoder resolution, pressure noise (sim/sensors.hpp)
//   [rig.lvdt]                the spool LVDT and its anti-aliasing stage (sim/lvdt_sensor.hpp)
// A key left out keeps the papers' value. Every key has bounds, stated once in rig_settings.cpp,
// and the combinations a rig cannot have are refused (a rod as wide as the bore, a proportional
// valve whose dead band leaves it no current to open fully, ...), each as a ConfigError at the
// offending key.
#pragma once

#include <array>
#include <string_view>

#include "drivers/table_reader.hpp"
#include "sim/rig.hpp"

namespace hsa::io::sim_plugin {

// The settings keys read_rig_config reads, for the reader's reject_unknown_keys.
inline constexpr std::array<std::string_view, 6> kRigConfigKeys = {"valve",  "load_kg", "initial_position_m",
                                                                   "seed",   "step_s",  "rig"};

// Throws ConfigError for a value out of its bounds, an unknown key in [rig] or its groups, or an
// inconsistent combination. Keys outside kRigConfigKeys are the caller's to check.
[[nodiscard]] sim::RigConfig read_rig_config(const TableReader& settings);

}  // namespace hsa::io::sim_plugin
