// Writing the plant-set file (plant_set_file.hpp): every number in the shortest form that reads
// back as the same double, and comments that say what each table is for a reader of the
// file; docs/plant-set.md has the full description.
#include <charconv>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>

#include "plant_set/plant_set_file.hpp"

namespace hsa::plant_set {
namespace {

std::string number(double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("plant set: a number is not finite");
  char text[40];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;  // shortest that reads back exactly
  return std::string(text, end);
}

// A TOML basic string; control characters are refused rather than escaped: a run's file name has none.
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw std::invalid_argument("plant set: the name \"" + text + "\" has a control character");
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void estimate(std::ostream& out, const std::string& key, const control::identification::Estimate& e) {
  out << key << " = " << number(e.value) << "\n" << key << "_std = " << number(e.std_dev) << "\n";
}

void direction(std::ostream& out, const char* name, const control::identification::DirectionCapability& d) {
  out << "\n[capability." << name << "]\n"
      << "max_speed_m_s = " << number(d.max_speed_m_s) << "\n"
      << "max_acceleration_m_s2 = " << number(d.max_acceleration_m_s2) << "\n"
      << "speed_limit_m_s = " << number(d.speed_limit_m_s) << "\n"
      << "acceleration_limit_m_s2 = " << number(d.acceleration_limit_m_s2) << "\n"
      << "speed_pump_limited = " << (d.speed_pump_limited ? "true" : "false") << "\n"
      << "acceleration_force_limited = " << (d.acceleration_force_limited ? "true" : "false") << "\n"
      << "worst_run = " << quoted(d.worst_run) << "\n"
      << "load_kg = " << number(d.load_kg) << "\n";
}

}  // namespace

void write_plant_set(std::ostream& out, const control::PlantSet& set) {
  if (set.plants.empty()) throw std::invalid_argument("plant set: no plant");
  if (set.nominal >= set.plants.size()) throw std::invalid_argument("plant set: the nominal index is out of range");
  out << "# Plants identified at several working points of one axis (hsa-analyze identify --set).\n"
         "# Format: docs/plant-set.md. SI units, named in the keys; the paper's (Puglisi et al. 2015)\n"
         "# b0, b1 are the same numbers, its k01 in mm/s is k01_m_s * 1000.\n"
      << "format = " << quoted(std::string(kFormatName)) << "\n"
      << "version = " << control::PlantSet::kFormatVersion << "\n"
      << "# [[plant]] index (from 0) of the nominal plant, eq 49: the best summed fit over every run\n"
      << "nominal = " << set.nominal << "\n"
      << "# the nameplate and geometry the capability was computed with\n"
      << "supply_pressure_pa = " << number(set.supply_pressure_pa) << "\n"
      << "pump_flow_m3_per_s = " << number(set.pump_flow_m3_per_s) << "\n"
      << "piston_area_m2 = " << number(set.piston_area_m2) << "\n"
      << "area_ratio = " << number(set.area_ratio) << "\n"
      << "\n# what the valve can give at the worst load among the runs; *_limit = margin * max\n"
      << "[capability]\nmargin = " << number(set.capability.margin) << "\n";
  direction(out, "extend", set.capability.extend);
  direction(out, "retract", set.capability.retract);
  for (const control::PlantSetEntry& p : set.plants) {
    out << "\n[[plant]]\nname = " << quoted(p.name) << "\n"
        << "position_m = " << number(p.position_m) << "\n"
        << "load_kg = " << number(p.load_kg) << "\n";
    estimate(out, "b0_per_s2", p.b0_per_s2);
    estimate(out, "b1_per_s", p.b1_per_s);
    estimate(out, "k01_m_s", p.k01_m_s);
    estimate(out, "k01_retracting_m_s", p.k01_retracting_m_s);
    out << "delay_s = " << number(p.delay_s) << "\n"
        << "kp_per_m = " << number(p.kp_per_m) << "\n"
        << "fit_index = " << number(p.fit_index) << "\n"
        << "nominal_score = " << number(p.nominal_score) << "\n";
  }
  if (!out) throw std::invalid_argument("plant set: the output could not be written");
}

}  // namespace hsa::plant_set
