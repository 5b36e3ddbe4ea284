#include "drivers/sim/scenario_event.hpp"

#include <string>

namespace hsa::io::sim_plugin {
namespace {

// Fails at whichever of the two keys is present when the other is not.
void require_together(const TableReader& s, std::string_view a, std::string_view b) {
  if (s.has(a) == s.has(b)) return;
  const std::string_view present = s.has(a) ? a : b;
  const std::string_view missing = s.has(a) ? b : a;
  s.fail(present, s.key_path(missing) + " beside it");
}

}  // namespace

Event parse_event(const TableReader& s) {
  s.reject_unknown_keys({"at_s", "estop", "load_kg", "valve_stuck", "supply_lost", "sensor", "fault",
                         "encoder_jump_m", "encoder_stale", "driver_error", "driver_error_s",
                         "stall_us", "stall_cycles"});
  Event e;
  e.at_s = s.number("at_s", NumberRange::non_negative());
  if (s.has("estop")) e.estop = s.boolean("estop");
  if (s.has("load_kg")) e.load_kg = s.number("load_kg", NumberRange::non_negative());
  if (s.has("valve_stuck")) e.valve_stuck = s.boolean("valve_stuck");
  if (s.has("supply_lost")) e.supply_lost = s.boolean("supply_lost");
  require_together(s, "sensor", "fault");
  if (s.has("sensor")) {
    const std::string sensor = s.choice("sensor", {"encoder", "pressure_a", "pressure_b", "spool_lvdt", "valve_current"});
    e.sensor = sensor == "encoder"      ? Sensor::encoder
               : sensor == "pressure_a" ? Sensor::pressure_a
               : sensor == "pressure_b" ? Sensor::pressure_b
               : sensor == "spool_lvdt" ? Sensor::spool_lvdt
                                        : Sensor::valve_current;
    const std::string fault = s.choice("fault", {"none", "stuck", "disconnected"});
    e.fault = fault == "none"    ? sim::SensorFaultMode::none
              : fault == "stuck" ? sim::SensorFaultMode::stuck
                                 : sim::SensorFaultMode::disconnected;
  }
  if (s.has("encoder_jump_m")) e.encoder_jump_m = s.number("encoder_jump_m", NumberRange::any());
  if (s.has("encoder_stale")) e.encoder_stale = s.boolean("encoder_stale");
  if (s.has("driver_error")) e.driver_error = s.boolean("driver_error");
  if (s.has("driver_error_s")) {
    if (!e.driver_error.value_or(false)) s.fail("driver_error_s", "only beside driver_error = true");
    e.driver_error_s = s.number("driver_error_s", NumberRange{.min = 0.0, .max = 86400.0, .min_exclusive = true});
  }
  require_together(s, "stall_us", "stall_cycles");
  if (s.has("stall_us")) {
    e.stall_us = s.integer("stall_us", 1, 1'000'000);
    e.stall_cycles = s.integer("stall_cycles", 1, 1'000'000);
  }
  if (!e.estop && !e.load_kg && !e.valve_stuck && !e.supply_lost && !e.sensor && !e.encoder_jump_m &&
      !e.encoder_stale && !e.driver_error && !e.stall_us) {
    s.fail_here("expected at least one change beside at_s");
  }
  return e;
}

}  // namespace hsa::io::sim_plugin
