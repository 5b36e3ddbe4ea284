// One scripted change to the simulated rig, read from an [[events]] table of the sim plugin's
// settings (the keys are listed in drivers/sim/sim_driver.cpp). The daemon's end-to-end tests
// reach the rig only through its configuration, so their scenarios are written as these events.
#pragma once

#include <cstdint>
#include <optional>

#include "drivers/table_reader.hpp"
#include "sim/faults.hpp"

namespace hsa::io::sim_plugin {

enum class Sensor { encoder, pressure_a, pressure_b, spool_lvdt, valve_current };

// Every field that is set is applied at `at_s` of simulated time.
struct Event {
  double at_s = 0.0;
  std::optional<bool> estop;
  std::optional<double> load_kg;
  std::optional<bool> valve_stuck;
  std::optional<bool> supply_lost;
  std::optional<Sensor> sensor;
  sim::SensorFaultMode fault = sim::SensorFaultMode::none;
  std::optional<double> encoder_jump_m;
  std::optional<bool> encoder_stale;
  std::optional<bool> driver_error;
  std::optional<double> driver_error_s;  // with driver_error = true: the outage's length
  std::optional<std::int64_t> stall_us;  // with stall_cycles
  std::int64_t stall_cycles = 0;
};

// Throws ConfigError for an unknown key, a value out of range, keys that must come in pairs and
// come alone, and an event that changes nothing.
Event parse_event(const TableReader& s);

}  // namespace hsa::io::sim_plugin
