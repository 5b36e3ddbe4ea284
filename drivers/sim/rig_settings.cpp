#include "drivers/sim/rig_settings.hpp"

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace hsa::io::sim_plugin {
namespace {

// One physical parameter: its key, its bounds (what any rig of this kind could have, wide enough
// for a rig other than the paper's, narrow enough to refuse a unit slip such as bar for Pa or mm
// for m), the unit its message names, and where it goes in the RigConfig.
struct Parameter {
  std::string_view key;
  NumberRange range;
  std::string_view unit;
  void (*set)(sim::RigConfig&, double);
};

struct Group {
  std::string_view table;
  std::span<const Parameter> parameters;
};

constexpr NumberRange closed(double min, double max) { return {.min = min, .max = max}; }
// (min, max]: zero or below is not a size, a mass or a rate.
constexpr NumberRange above(double min, double max) { return {.min = min, .max = max, .min_exclusive = true}; }
// [min, max): a stop that must stay on one side of hydraulic zero.
constexpr NumberRange below(double min, double max) { return {.min = min, .max = max, .max_exclusive = true}; }

using C = sim::RigConfig;

constexpr Parameter kCylinder[] = {
    {"stroke_m", closed(0.01, 5.0), "m", [](C& c, double v) { c.cylinder.geometry.stroke_m = v; }},
    {"bore_m", closed(0.005, 0.5), "m", [](C& c, double v) { c.cylinder.geometry.bore_m = v; }},
    {"rod_m", closed(0.002, 0.4), "m", [](C& c, double v) { c.cylinder.geometry.rod_m = v; }},
    // Oil trapped beyond the piston's sweep (hoses, manifold, ports) as a length of bore; zero
    // would make a chamber's stiffness infinite at its end stop.
    {"dead_length_m", closed(0.001, 2.0), "m", [](C& c, double v) { c.cylinder.geometry.dead_length_m = v; }},
    {"gravity_m_per_s2", closed(0.0, 20.0), "m/s²", [](C& c, double v) { c.cylinder.gravity_m_per_s2 = v; }},
    {"static_friction_n", closed(0.0, 1e5), "N", [](C& c, double v) { c.cylinder.static_friction_n = v; }},
    {"coulomb_friction_n", closed(0.0, 1e5), "N", [](C& c, double v) { c.cylinder.coulomb_friction_n = v; }},
    {"stick_velocity_m_per_s", above(0.0, 0.01), "m/s",
     [](C& c, double v) { c.cylinder.stick_velocity_m_per_s = v; }},
    // Some leakage is needed: it is what sets the chamber pressures of a closed valve.
    {"null_leakage_m3_per_s", above(0.0, 1e-4), "m³/s",
     [](C& c, double v) { c.cylinder.null_leakage_m3_per_s = v; }},
};

constexpr Parameter kDynamics[] = {
    {"moving_mass_kg", closed(0.01, 1e4), "kg", [](C& c, double v) { c.cylinder.dynamics.moving_mass_kg = v; }},
    {"viscous_damping_n_s_per_m", closed(0.0, 1e6), "N·s/m",
     [](C& c, double v) { c.cylinder.dynamics.viscous_damping_n_s_per_m = v; }},
    // Effective: oil with its hoses and entrained air, up to oil in steel pipes (mineral oil
    // ≈ 1.5e9 Pa). The paper's rig identifies as 6e6-1.9e7 Pa (identified_parameters.hpp).
    {"bulk_modulus_pa", closed(1e6, 3e9), "Pa", [](C& c, double v) { c.cylinder.dynamics.bulk_modulus_pa = v; }},
    {"flow_coefficient_m3_per_s_per_sqrt_pa", closed(1e-10, 1e-4), "m³/s per √Pa",
     [](C& c, double v) { c.cylinder.dynamics.flow_coefficient = v; }},
};

constexpr Parameter kSupply[] = {
    {"supply_pressure_pa", closed(1e5, 4e7), "Pa", [](C& c, double v) { c.supply.supply_pressure_pa = v; }},
    {"pump_flow_m3_per_s", closed(1e-7, 1e-2), "m³/s", [](C& c, double v) { c.supply.pump_flow_m3_per_s = v; }},
};

constexpr Parameter kServoValve[] = {
    {"bandwidth_hz", closed(1.0, 1000.0), "Hz", [](C& c, double v) { c.servo_valve.bandwidth_hz = v; }},
    {"damping_ratio", closed(0.05, 5.0), "(dimensionless)", [](C& c, double v) { c.servo_valve.damping_ratio = v; }},
};

constexpr Parameter kProportionalValve[] = {
    {"current_delay_s", closed(1e-5, 0.01), "s", [](C& c, double v) { c.proportional_valve.current_delay_s = v; }},
    {"current_error_max_a", closed(0.0, 0.1), "A",
     [](C& c, double v) { c.proportional_valve.current_error_max_a = v; }},
    {"current_max_a", closed(0.1, 20.0), "A", [](C& c, double v) { c.proportional_valve.current_max_a = v; }},
    {"hysteresis_width_a", closed(0.0, 20.0), "A",
     [](C& c, double v) { c.proportional_valve.hysteresis_width_a = v; }},
    {"magnetic_lag_s", closed(1e-5, 0.1), "s", [](C& c, double v) { c.proportional_valve.magnetic_lag_s = v; }},
    {"force_constant_n_per_a", closed(0.1, 1000.0), "N/A",
     [](C& c, double v) { c.proportional_valve.force_constant_n_per_a = v; }},
    {"moving_mass_kg", closed(1e-3, 10.0), "kg", [](C& c, double v) { c.proportional_valve.moving_mass_kg = v; }},
    // The spool is integrated in 25 µs substeps: ω·h stays below 0.16 up to 1 kHz.
    {"natural_frequency_hz", closed(1.0, 1000.0), "Hz",
     [](C& c, double v) { c.proportional_valve.natural_frequency_hz = v; }},
    {"damping_ratio", closed(0.0, 5.0), "(dimensionless)", [](C& c, double v) { c.proportional_valve.damping_ratio = v; }},
    {"coulomb_friction_n", closed(0.0, 100.0), "N",
     [](C& c, double v) { c.proportional_valve.coulomb_friction_n = v; }},
    {"stroke_min_m", below(-0.05, 0.0), "m", [](C& c, double v) { c.proportional_valve.stroke_min_m = v; }},
    {"stroke_max_m", above(0.0, 0.05), "m", [](C& c, double v) { c.proportional_valve.stroke_max_m = v; }},
    {"opening_span_m", above(0.0, 0.05), "m", [](C& c, double v) { c.proportional_valve.opening_span_m = v; }},
    {"fail_safe_closed_m", below(-0.05, 0.0), "m",
     [](C& c, double v) { c.proportional_valve.fail_safe_closed_m = v; }},
};

constexpr Parameter kSensors[] = {
    // 0: the exact position, no quantization.
    {"encoder_resolution_m", closed(0.0, 1e-3), "m", [](C& c, double v) { c.sensors.encoder_resolution_m = v; }},
    {"pressure_noise_std_pa", closed(0.0, 1e6), "Pa", [](C& c, double v) { c.sensors.pressure_noise_std_pa = v; }},
};

constexpr Parameter kLvdt[] = {
    {"bandwidth_hz", closed(1.0, 1e5), "Hz", [](C& c, double v) { c.sensors.lvdt.bandwidth_hz = v; }},
    {"gain_v_per_m", above(0.0, 1e6), "V/m", [](C& c, double v) { c.sensors.lvdt.gain_v_per_m = v; }},
    {"scale_factor_error", closed(-0.5, 0.5), "(dimensionless)", [](C& c, double v) { c.sensors.lvdt.scale_factor_error = v; }},
    {"bias_m", closed(-0.01, 0.01), "m", [](C& c, double v) { c.sensors.lvdt.bias_m = v; }},
    {"output_limit_v", above(0.0, 100.0), "V", [](C& c, double v) { c.sensors.lvdt.output_limit_v = v; }},
    {"excitation_hz", closed(0.0, 1e5), "Hz", [](C& c, double v) { c.sensors.lvdt.excitation_hz = v; }},
    {"noise_density_m_per_sqrt_hz", closed(0.0, 1e-3), "m/√Hz",
     [](C& c, double v) { c.sensors.lvdt.noise_density_m_per_sqrt_hz = v; }},
    // At most 1e4 ADC samples in the longest step (1 ms).
    {"adc_rate_hz", closed(1e3, 1e7), "Hz", [](C& c, double v) { c.sensors.lvdt.adc_rate_hz = v; }},
    {"anti_aliasing_hz", above(0.0, 2.5e6), "Hz", [](C& c, double v) { c.sensors.lvdt.anti_aliasing_hz = v; }},
};

constexpr Group kGroups[] = {
    {"cylinder", kCylinder},       {"dynamics", kDynamics},
    {"supply", kSupply},           {"servo_valve", kServoValve},
    {"proportional_valve", kProportionalValve},
    {"sensors", kSensors},         {"lvdt", kLvdt},
};

std::string expected_of(const NumberRange& range, std::string_view unit) {
  return range.expected() + " " + std::string(unit);
}

// A group's table, or an empty one when the configuration leaves the group out, and its key path
// for messages that name a parameter beside the refused one.
struct GroupReader {
  TableReader reader;
  std::string path;

  [[nodiscard]] bool has(std::string_view key) const { return reader.has(key); }
  [[noreturn]] void fail(std::string_view key, std::string_view expected) const { reader.fail(key, expected); }
  [[nodiscard]] std::string quantity(std::string_view key, double value, std::string_view unit) const {
    return path + "." + std::string(key) + " = " + format_setting(value) + " " + std::string(unit);
  }
};

// A number in its bounds, or nothing when the key is absent.
std::optional<double> read(const TableReader& t, std::string_view key, const NumberRange& range,
                           std::string_view unit) {
  const toml::node* node = t.table().get(key);
  if (node == nullptr) return std::nullopt;
  const std::optional<double> value = node->is_number() ? node->value<double>() : std::nullopt;
  if (!value || !range.contains(*value)) t.fail(key, expected_of(range, unit));
  return value;
}

// Parameters that disagree are refused at the first of them the configuration wrote (the defaults
// agree, so it wrote at least one), each with what it should have been.
struct Candidate {
  std::string_view key;
  std::string expected;
};
[[noreturn]] void refuse(const GroupReader& g, std::initializer_list<Candidate> candidates) {
  for (const Candidate& c : candidates) {
    if (g.has(c.key)) g.fail(c.key, c.expected);
  }
  g.fail(candidates.begin()->key, candidates.begin()->expected);
}

void check_cylinder(const GroupReader& g, const sim::CylinderParameters& c) {
  const sim::CylinderGeometry& geometry = c.geometry;
  if (!(geometry.rod_m < geometry.bore_m)) {
    refuse(g, {{"rod_m", "a rod diameter below the bore, " + g.quantity("bore_m", geometry.bore_m, "m")},
               {"bore_m", "a bore wider than the rod, " + g.quantity("rod_m", geometry.rod_m, "m")}});
  }
  // Sliding friction above breakaway is no seal the rig could have.
  if (!(c.coulomb_friction_n <= c.static_friction_n)) {
    refuse(g, {{"coulomb_friction_n",
                "at most the static friction, " + g.quantity("static_friction_n", c.static_friction_n, "N")},
               {"static_friction_n",
                "at least the sliding friction, " + g.quantity("coulomb_friction_n", c.coulomb_friction_n, "N")}});
  }
}

// opening() of sim/proportional_valve.hpp needs, in spool position from hydraulic zero:
// stroke_min <= fail_safe_closed < -opening_span < 0 < opening_span <= stroke_max. And the
// regulator must be able to open the valve fully: the force-equivalent current at full opening
// plus the whole magnetic dead band (the rising edge lags by its full width, eq 6 of Canuto et al.
// 2014) must fit under I_max, or a valve loop saturates short of full flow.
void check_proportional_valve(const GroupReader& g, const sim::ProportionalValveParameters& p) {
  if (!(p.opening_span_m <= p.stroke_max_m)) {
    refuse(g, {{"opening_span_m", "at most the end stop, " + g.quantity("stroke_max_m", p.stroke_max_m, "m")},
               {"stroke_max_m", "at least the full opening, " + g.quantity("opening_span_m", p.opening_span_m, "m")}});
  }
  if (!(p.fail_safe_closed_m < -p.opening_span_m)) {
    refuse(g, {{"fail_safe_closed_m",
                "below the full negative opening, -" + g.quantity("opening_span_m", p.opening_span_m, "m")},
               {"opening_span_m", "less than the fail-safe edge's depth, " +
                                      g.quantity("fail_safe_closed_m", p.fail_safe_closed_m, "m")}});
  }
  if (!(p.stroke_min_m <= p.fail_safe_closed_m)) {
    refuse(g, {{"stroke_min_m",
                "at most the fail-safe edge, " + g.quantity("fail_safe_closed_m", p.fail_safe_closed_m, "m")},
               {"fail_safe_closed_m", "at least the rest stop, " + g.quantity("stroke_min_m", p.stroke_min_m, "m")}});
  }
  const double stiffness = sim::ProportionalValve(p, p.current_delay_s).spring_stiffness();
  const double full_open_a =
      stiffness * (p.opening_span_m - p.stroke_min_m) / p.force_constant_n_per_a + p.hysteresis_width_a;
  if (!(full_open_a <= p.current_max_a)) {
    const std::string expected = "a valve the current can open fully: spring force at full opening / force "
                                 "constant + dead band = " + format_setting(full_open_a) + " A must be at most " +
                                 g.quantity("current_max_a", p.current_max_a, "A");
    refuse(g, {{"hysteresis_width_a", expected},
               {"current_max_a", expected},
               {"force_constant_n_per_a", expected},
               {"natural_frequency_hz", expected},
               {"moving_mass_kg", expected},
               {"opening_span_m", expected},
               {"stroke_min_m", expected}});
  }
}

void check_lvdt(const GroupReader& g, const sim::LvdtParameters& l) {
  if (l.anti_aliasing_order > 0 && !(l.anti_aliasing_hz < 0.25 * l.adc_rate_hz)) {
    const std::string expected = "an anti-aliasing cut-off below a quarter of the ADC rate, " +
                                 g.quantity("anti_aliasing_hz", l.anti_aliasing_hz, "Hz") + " and " +
                                 g.quantity("adc_rate_hz", l.adc_rate_hz, "Hz");
    refuse(g, {{"anti_aliasing_hz", expected}, {"adc_rate_hz", expected}});
  }
}

}  // namespace

sim::RigConfig read_rig_config(const TableReader& s) {
  sim::RigConfig config;
  const std::optional<TableReader> rig = s.table("rig", false, "a table of the rig's physical parameters");
  if (rig) {
    std::vector<std::string_view> names;
    for (const Group& g : kGroups) names.push_back(g.table);
    rig->reject_unknown_keys(names);
  }
  static const toml::table empty;
  std::vector<GroupReader> groups;  // as kGroups
  for (const Group& g : kGroups) {
    const std::string path = s.key_path("rig") + "." + std::string(g.table);
    std::optional<TableReader> t;
    if (rig) t = rig->table(g.table, false, "a table of " + std::string(g.table) + " parameters");
    groups.push_back({t ? *t : TableReader::of(empty), path});
    if (!t) continue;
    std::vector<std::string_view> keys;
    for (const Parameter& p : g.parameters) keys.push_back(p.key);
    if (g.table == "lvdt") keys.push_back("anti_aliasing_order");
    t->reject_unknown_keys(keys);
    for (const Parameter& p : g.parameters) {
      if (const std::optional<double> v = read(*t, p.key, p.range, p.unit)) p.set(config, *v);
    }
  }
  const GroupReader& cylinder = groups[0];
  const GroupReader& proportional = groups[4];
  const GroupReader& lvdt = groups[6];

  // 0 (no filter) or an even order up to 8: the Butterworth cascade is built of second-order sections.
  const std::int64_t order =
      lvdt.reader.integer("anti_aliasing_order", 0, 8, config.sensors.lvdt.anti_aliasing_order);
  if (order % 2 != 0) lvdt.fail("anti_aliasing_order", "0 or an even integer in [2, 8]");
  config.sensors.lvdt.anti_aliasing_order = static_cast<int>(order);
  check_lvdt(lvdt, config.sensors.lvdt);
  check_cylinder(cylinder, config.cylinder);
  check_proportional_valve(proportional, config.proportional_valve);

  config.valve = s.choice("valve", {"servo", "proportional"}, "servo") == "servo" ? sim::ValveKind::servo
                                                                                   : sim::ValveKind::proportional;
  if (const auto load = read(s, "load_kg", NumberRange::non_negative(), "kg")) config.load_kg = *load;
  const double stroke = config.cylinder.geometry.stroke_m;
  const NumberRange positions = closed(0.0, stroke);
  if (const auto y = read(s, "initial_position_m", positions,
                          "m, within the stroke " + cylinder.quantity("stroke_m", stroke, "m"))) {
    config.initial_position_m = *y;
  } else if (!positions.contains(config.initial_position_m)) {
    cylinder.fail("stroke_m", "a stroke that holds the initial position, initial_position_m = " +
                                  format_setting(config.initial_position_m) + " m");
  }
  config.seed = static_cast<std::uint64_t>(
      s.integer("seed", 0, std::numeric_limits<std::int64_t>::max(), static_cast<std::int64_t>(config.seed)));
  if (const auto step = read(s, "step_s", above(0.0, 1e-3), "s")) config.step_s = *step;
  // The proportional valve's regulator delays the current by whole steps, at least one.
  const double delay = config.proportional_valve.current_delay_s;
  if (!(config.step_s <= delay)) {
    if (s.has("step_s")) {
      s.fail("step_s", "at most the proportional valve's current delay, " +
                           proportional.quantity("current_delay_s", delay, "s"));
    }
    proportional.fail("current_delay_s", "at least one step, step_s = " + format_setting(config.step_s) + " s");
  }
  return config;
}

}  // namespace hsa::io::sim_plugin
