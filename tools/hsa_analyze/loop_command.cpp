// hsa-analyze loop: the PI cylinder loop on the identified plants (Puglisi et al. 2015, section 4):
// Table A3's 33 and eq 52's nominal by default, or those of a plant-set file (--plants, written by
// `hsa-analyze identify --set`, docs/plant-set.md) with its own nominal.
#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <optional>
#include <stdexcept>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "control/loop_analysis.hpp"
#include "control/plant_table.hpp"
#include "drivers/config_error.hpp"
#include "plant_set/plant_set_file.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/json_list.hpp"
#include "tools/hsa_analyze/working_point.hpp"

namespace hsa::analyze {

namespace {

using control::CylinderPlant;
using control::LoopAnalysis;

struct NamedPlant {
  std::string name;  // as the user would select it: "nominal" or "<position_m>:<load_kg>"
  std::string description;
  CylinderPlant plant;
};

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

std::string row_name(const control::IdentifiedPlant& row) {
  return format("%g", row.position_m()) + ":" + std::to_string(row.load_kg);
}

NamedPlant named(const control::IdentifiedPlant& row) {
  return {row_name(row),
          "Table A3, " + std::to_string(row.position_mm) + " mm, " + std::to_string(row.load_kg) + " kg",
          row.plant()};
}

std::string table_a3_points() {
  std::string positions;
  for (std::size_t k = 0; k < control::kTableA3.size(); k += 3) {
    if (!positions.empty()) positions += ", ";
    positions += format("%g", control::kTableA3[k].position_m());
  }
  return "Table A3 has positions " + positions + " m and loads 0, 3, 6 kg";
}


std::string set_name(const control::PlantSetEntry& p) {
  return format("%g", p.position_m) + ":" + format("%g", p.load_kg);
}

NamedPlant named(const control::PlantSetEntry& p, const std::string& file) {
  return {set_name(p), file + ", " + p.name, p.plant()};
}

// The same selections on a plant set: its nominal, all its plants, or the one at a working point
// (matched to 0.5 mm and 0.05 kg: an identified position is a mean setpoint, not a round number).
std::vector<NamedPlant> select_set_plants(const std::string& selection, const std::string& file) {
  control::PlantSet set;
  try {
    set = plant_set::load_plant_set(file);
  } catch (const io::ConfigError& e) {
    throw CLI::ValidationError("--plants", e.what());
  }
  if (selection == "nominal") {
    NamedPlant p = named(set.plants[set.nominal], file);
    p.description += ", nominal (eq 49)";
    return {p};
  }
  std::vector<NamedPlant> plants;
  if (selection == "all") {
    for (const auto& p : set.plants) plants.push_back(named(p, file));
    return plants;
  }
  const std::optional<WorkingPoint> point = parse_working_point(selection);
  if (!point) {
    throw CLI::ValidationError("--plant", "expected nominal, all or <position_m>:<load_kg> (e.g. 0.15:3), got '" +
                                              selection + "'");
  }
  std::string points;
  for (const auto& p : set.plants) {
    if (std::abs(p.position_m - point->position_m) <= 5e-4 && std::abs(p.load_kg - point->load_kg) <= 0.05)
      plants.push_back(named(p, file));
    points += (points.empty() ? "" : ", ") + set_name(p);
  }
  if (plants.empty())
    throw CLI::ValidationError("--plant", "no plant of " + file + " at " + selection + "; it has " + points);
  return plants;
}

std::vector<NamedPlant> select_plants(const std::string& selection) {
  if (selection == "nominal")
    return {{"nominal", "eq 52, P0 = 1.722e6 / (s^3 + 90.31 s^2 + 7692 s)", control::kNominalPlant}};
  std::vector<NamedPlant> plants;
  if (selection == "all") {
    for (const auto& row : control::kTableA3) plants.push_back(named(row));
    return plants;
  }
  const std::optional<WorkingPoint> point = parse_working_point(selection);
  if (!point) {
    throw CLI::ValidationError("--plant", "expected nominal, all or <position_m>:<load_kg> (e.g. 0.12:6), got '" +
                                              selection + "'");
  }
  const auto row = control::find_identified_plant(point->position_m, point->load_kg);
  if (!row) {
    throw CLI::ValidationError("--plant", "no identified plant at " + format("%g", point->position_m) + " m, " +
                                              format("%g", point->load_kg) + " kg; " + table_a3_points());
  }
  plants.push_back(named(*row));
  return plants;
}

// Conjugate pairs printed once, as a ± b j.
std::string poles_text(const std::vector<std::complex<double>>& poles) {
  std::string text;
  for (const auto& p : poles) {
    if (p.imag() < 0.0) continue;
    if (!text.empty()) text += ", ";
    text += format("%.2f", p.real());
    if (p.imag() > 0.0) text += " ± " + format("%.2fj", p.imag());
  }
  return text;
}

nlohmann::ordered_json json_object(const std::string& plant, const LoopAnalysis& a) {
  nlohmann::ordered_json poles = nlohmann::ordered_json::array();
  for (const auto& p : a.poles) poles.push_back({p.real(), p.imag()});
  return {{"plant", plant},
          {"poles", std::move(poles)},
          {"gain_margin_db", a.margins.gain_margin_db},
          {"phase_margin_deg", a.margins.phase_margin_deg},
          {"crossover_rad_s", a.margins.crossover_rad_s},
          {"overshoot_pct", a.step.overshoot_pct},
          {"settling_s", a.step.settling_s}};
}

// The worst value of each metric over several plants, and which plant it came from.
struct WorstCase {
  LoopAnalysis values;
  std::string gain_margin, phase_margin, crossover, overshoot, settling, poles;
};

// NaN (unstable, or never settling) counts as worse than any number.
bool worse_high(double candidate, double current) { return std::isnan(candidate) || candidate > current; }
bool worse_low(double candidate, double current) { return std::isnan(candidate) || candidate < current; }

WorstCase worst_case(const std::vector<NamedPlant>& plants, const std::vector<LoopAnalysis>& results) {
  WorstCase w{results.front(), plants.front().name, plants.front().name, plants.front().name,
              plants.front().name, plants.front().name, plants.front().name};
  for (std::size_t k = 1; k < results.size(); ++k) {
    const LoopAnalysis& a = results[k];
    const std::string& name = plants[k].name;
    // Keeps `candidate` and the plant's name when it is worse than the worst so far.
    const auto keep_worse = [&](bool (*worse)(double, double), double candidate, double& worst, std::string& plant) {
      if (!worse(candidate, worst)) return;
      worst = candidate;
      plant = name;
    };
    keep_worse(worse_low, a.margins.gain_margin_db, w.values.margins.gain_margin_db, w.gain_margin);
    keep_worse(worse_low, a.margins.phase_margin_deg, w.values.margins.phase_margin_deg, w.phase_margin);
    keep_worse(worse_low, a.margins.crossover_rad_s, w.values.margins.crossover_rad_s, w.crossover);
    keep_worse(worse_high, a.step.overshoot_pct, w.values.step.overshoot_pct, w.overshoot);
    keep_worse(worse_high, a.step.settling_s, w.values.step.settling_s, w.settling);
    if (a.poles.front().real() > w.values.poles.front().real()) {
      w.values.poles = a.poles;
      w.poles = name;
    }
    w.values.stable = w.values.stable && a.stable;
  }
  return w;
}

void print_text(const std::vector<NamedPlant>& plants, const std::vector<LoopAnalysis>& results) {
  for (std::size_t k = 0; k < plants.size(); ++k) {
    const LoopAnalysis& a = results[k];
    std::printf("%s (%s)%s\n", plants[k].name.c_str(), plants[k].description.c_str(),
                a.stable ? "" : "  UNSTABLE");
    std::printf("  closed-loop poles  %s\n", poles_text(a.poles).c_str());
    std::printf("  gain margin        %.2f dB at %.2f rad/s\n", a.margins.gain_margin_db,
                a.margins.phase_crossover_rad_s);
    std::printf("  phase margin       %.2f deg at crossover %.2f rad/s\n", a.margins.phase_margin_deg,
                a.margins.crossover_rad_s);
    std::printf("  step               overshoot %.2f %%, 2 %% settling %.3f s\n", a.step.overshoot_pct,
                a.step.settling_s);
  }
  if (plants.size() > 1) {
    const WorstCase w = worst_case(plants, results);
    const auto stable = std::count_if(results.begin(), results.end(), [](const LoopAnalysis& a) { return a.stable; });
    std::printf("worst case over %zu plants (stable on %td of them)\n", plants.size(), stable);
    std::printf("  slowest poles      %s (%s)\n", poles_text(w.values.poles).c_str(), w.poles.c_str());
    std::printf("  gain margin        %.2f dB (%s)\n", w.values.margins.gain_margin_db, w.gain_margin.c_str());
    std::printf("  phase margin       %.2f deg (%s)\n", w.values.margins.phase_margin_deg, w.phase_margin.c_str());
    std::printf("  lowest crossover   %.2f rad/s (%s)\n", w.values.margins.crossover_rad_s, w.crossover.c_str());
    std::printf("  overshoot          %.2f %% (%s)\n", w.values.step.overshoot_pct, w.overshoot.c_str());
    std::printf("  2 %% settling       %.3f s (%s)\n", w.values.step.settling_s, w.settling.c_str());
  }
}

void print_json(const std::vector<NamedPlant>& plants, const std::vector<LoopAnalysis>& results) {
  JsonList list;
  for (std::size_t k = 0; k < plants.size(); ++k) list.add(json_object(plants[k].name, results[k]));
  if (plants.size() > 1) {
    // One more object with the same keys, each holding the worst value over the plants, and
    // "worst_of" naming the plant each came from ("poles" are the slowest plant's).
    const WorstCase w = worst_case(plants, results);
    nlohmann::ordered_json worst = json_object("worst case", w.values);
    worst["worst_of"] = {{"poles", w.poles},         {"gain_margin_db", w.gain_margin},
                         {"phase_margin_deg", w.phase_margin}, {"crossover_rad_s", w.crossover},
                         {"overshoot_pct", w.overshoot}, {"settling_s", w.settling}};
    list.add(worst);
  }
  list.close();
}

}  // namespace

void add_loop_command(CLI::App& app) {
  struct Options {
    std::string plant = "nominal";
    double kp = 85.0;
    double ki = 460.0;
    bool json = false;
    std::string plants;
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "loop", "PI cylinder loop on the identified plants: poles, margins, linear step response");
  cmd->add_option("--plant", options->plant,
                  "nominal (eq 52), all (the 33 plants of Table A3), or <position_m>:<load_kg> (e.g. 0.12:6)")
      ->capture_default_str();
  cmd->add_option("--kp", options->kp, "proportional gain, valve opening per metre (m^-1)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--ki", options->ki, "integral gain, valve opening per metre-second (m^-1 s^-1)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--plants", options->plants,
                  "a plant-set file (hsa-analyze identify --set; docs/plant-set.md): --plant then selects its "
                  "nominal, all its plants, or one at <position_m>:<load_kg> instead of Table A3's")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", options->json, "print a JSON list, one object per plant");
  cmd->callback([options] {
    const std::vector<NamedPlant> plants = options->plants.empty()
                                               ? select_plants(options->plant)
                                               : select_set_plants(options->plant, options->plants);
    std::vector<LoopAnalysis> results;
    try {
      for (const NamedPlant& p : plants) results.push_back(control::analyze_loop(p.plant, {options->kp, options->ki}));
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("loop", e.what());
    }
    if (options->json) print_json(plants, results); else print_text(plants, results);
  });
}

}  // namespace hsa::analyze
