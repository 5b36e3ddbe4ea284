// Reading the plant-set file (plant_set_file.hpp). The bounds are those of a physical cylinder
// plant, wide enough for any rig hsad drives and narrow enough to catch a unit slip: b0 and b1
// positive, k01 in m/s (a value in the paper's mm/s, a thousand times larger, is out of range).
#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "drivers/config_error.hpp"
#include "drivers/table_reader.hpp"
#include "plant_set/plant_set_file.hpp"

namespace hsa::plant_set {
namespace {

using io::NumberRange;
using io::TableReader;

constexpr double kMaxPosition = 10.0;     // m: a stroke of a few metres, with room
constexpr double kMaxLoad = 1e5;          // kg
constexpr double kMaxB0 = 1e9;            // 1/s²: √b0 ≈ 5 kHz
constexpr double kMaxB1 = 1e6;            // 1/s
constexpr double kMaxSpeedGain = 100.0;   // m/s per unit opening
constexpr double kMaxDelay = 1.0;         // s
constexpr double kMaxAcceleration = 1e5;  // m/s²

control::identification::Estimate estimate(const TableReader& t, const std::string& key, const NumberRange& range) {
  return {t.number(key, range), t.number(key + "_std", NumberRange::closed(0.0, range.max))};
}

control::PlantSetEntry read_plant(const TableReader& t) {
  t.reject_unknown_keys({"name", "position_m", "load_kg", "b0_per_s2", "b0_per_s2_std", "b1_per_s", "b1_per_s_std",
                         "k01_m_s", "k01_m_s_std", "k01_retracting_m_s", "k01_retracting_m_s_std", "delay_s",
                         "kp_per_m", "fit_index", "nominal_score"});
  control::PlantSetEntry p;
  p.name = t.string("name", "a name for the working point, e.g. \"run-3kg.csv@3kg\"");
  if (p.name.empty()) t.fail("name", "a name that is not empty");
  p.position_m = t.number("position_m", NumberRange::closed(0.0, kMaxPosition));
  p.load_kg = t.number("load_kg", NumberRange::closed(0.0, kMaxLoad));
  p.b0_per_s2 = estimate(t, "b0_per_s2", NumberRange::positive(kMaxB0));
  p.b1_per_s = estimate(t, "b1_per_s", NumberRange::positive(kMaxB1));
  p.k01_m_s = estimate(t, "k01_m_s", NumberRange::positive(kMaxSpeedGain));
  p.k01_retracting_m_s = estimate(t, "k01_retracting_m_s", NumberRange::positive(kMaxSpeedGain));
  p.delay_s = t.number("delay_s", NumberRange::closed(0.0, kMaxDelay));
  p.kp_per_m = t.number("kp_per_m", NumberRange::positive(1e6));
  // Eq 39 is at most 1 and unbounded below; below −100 the model is not a model of the run.
  p.fit_index = t.number("fit_index", NumberRange::closed(-100.0, 1.0));
  p.nominal_score = t.number("nominal_score", NumberRange::closed(-1e6, 1e6));
  return p;
}

control::identification::DirectionCapability read_direction(const TableReader& t) {
  t.reject_unknown_keys({"max_speed_m_s", "max_acceleration_m_s2", "speed_limit_m_s", "acceleration_limit_m_s2",
                         "speed_pump_limited", "acceleration_force_limited", "worst_run", "load_kg"});
  control::identification::DirectionCapability d;
  d.max_speed_m_s = t.number("max_speed_m_s", NumberRange::positive(kMaxSpeedGain));
  d.max_acceleration_m_s2 = t.number("max_acceleration_m_s2", NumberRange::positive(kMaxAcceleration));
  d.speed_limit_m_s = t.number("speed_limit_m_s", NumberRange{.min = 0.0, .max = d.max_speed_m_s, .min_exclusive = true});
  d.acceleration_limit_m_s2 =
      t.number("acceleration_limit_m_s2", NumberRange{.min = 0.0, .max = d.max_acceleration_m_s2, .min_exclusive = true});
  d.speed_pump_limited = t.boolean("speed_pump_limited");
  d.acceleration_force_limited = t.boolean("acceleration_force_limited");
  d.worst_run = t.string("worst_run", "the name of the plant whose run set the limit");
  d.load_kg = t.number("load_kg", NumberRange::closed(0.0, kMaxLoad));
  return d;
}

control::PlantSet read(const TableReader& root) {
  root.reject_unknown_keys({"format", "version", "nominal", "supply_pressure_pa", "pump_flow_m3_per_s",
                            "piston_area_m2", "area_ratio", "capability", "plant"});
  const std::string format = root.string("format", "\"hsa-plant-set\"");
  if (format != kFormatName) root.fail("format", "\"hsa-plant-set\" (this is not a plant-set file)");
  (void)root.integer("version", control::PlantSet::kFormatVersion, control::PlantSet::kFormatVersion);

  control::PlantSet set;
  const std::vector<TableReader> plants = root.tables("plant");
  if (plants.empty()) root.fail("plant", "at least one [[plant]] table");
  for (const TableReader& t : plants) {
    control::PlantSetEntry p = read_plant(t);
    for (const control::PlantSetEntry& other : set.plants)
      if (other.name == p.name) t.fail("name", "a name no other plant has (\"" + p.name + "\" is taken)");
    set.plants.push_back(std::move(p));
  }
  set.nominal = static_cast<std::size_t>(root.integer("nominal", 0, static_cast<std::int64_t>(set.plants.size()) - 1));
  set.supply_pressure_pa = root.number("supply_pressure_pa", NumberRange::positive(1e9));
  set.pump_flow_m3_per_s = root.number("pump_flow_m3_per_s", NumberRange::positive(1.0));
  set.piston_area_m2 = root.number("piston_area_m2", NumberRange::positive(1.0));
  set.area_ratio = root.number("area_ratio", NumberRange{.min = 0.0, .max = 1.0, .min_exclusive = true});

  const TableReader cap = *root.table("capability", true, "a table [capability]");
  cap.reject_unknown_keys({"margin", "extend", "retract"});
  set.capability.margin = cap.number("margin", NumberRange{.min = 0.0, .max = 1.0, .min_exclusive = true});
  set.capability.extend = read_direction(*cap.table("extend", true, "a table [capability.extend]"));
  set.capability.retract = read_direction(*cap.table("retract", true, "a table [capability.retract]"));
  return set;
}

}  // namespace

control::PlantSet parse_plant_set(std::string_view text, std::string_view source_name) {
  const toml::table document = io::parse_toml(text, source_name);
  return read(TableReader::root(document, source_name));
}

control::PlantSet load_plant_set(const std::string& path) {
  std::ifstream file(path);
  if (!file.is_open()) throw io::ConfigError(path + ": cannot open the plant-set file");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_plant_set(text.str(), path);
}

}  // namespace hsa::plant_set
