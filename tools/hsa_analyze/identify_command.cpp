// `hsa-analyze identify RUN.csv`: the cylinder's plant at one working point from a closed-loop
// run recorded by `hsactl record` (Puglisi et al. 2015, section 3; the method is
// control/identification/identify_run.hpp), and the axis's capability at the run's load
// (axis_capability.hpp). `identify --set RUN@LOADkg ... --out FILE` identifies every run, picks the
// nominal plant by eq 49 and writes the plant-set file (identify_set.hpp, docs/plant-set.md).
// Each run's working point: its position is the run's mean setpoint, its load the `@<kg>kg` the
// operator appends to the file name (the load is put on the rod, not measured). This file reads
// the files and prints.
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "control/identification/identify_run.hpp"
#include "control/identification/identify_set.hpp"
#include "control/plant_table.hpp"
#include "control/setting_range.hpp"
#include "plant_set/plant_set_file.hpp"
#include "sim/cylinder_geometry.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"
#include "tools/hsa_analyze/working_point.hpp"

namespace hsa::analyze {
namespace {

using control::identification::Estimate;
using control::identification::Identification;

// Table A3's row closest to the identified plant (relative distance over b0, b1, k01).
control::IdentifiedPlant nearest_table_plant(const Identification& id) {
  const auto distance = [&](const control::IdentifiedPlant& row) {
    const auto rel = [](double a, double b) { return (a - b) / b; };
    return std::hypot(rel(id.plant.b0.value, row.b0), rel(id.plant.b1.value, row.b1),
                      rel(id.plant.k01.value, row.k01));
  };
  control::IdentifiedPlant best = control::kTableA3.front();
  for (const auto& row : control::kTableA3)
    if (distance(row) < distance(best)) best = row;
  return best;
}

nlohmann::ordered_json json(const Estimate& e) { return {{"value", e.value}, {"std_dev", e.std_dev}}; }

// The time series (measured and model) and the Bode of both plants, for tools/plot-experiments.
void write_plot_data(const std::string& prefix, const control::identification::ClosedLoopRun& run,
                     const Identification& id, const control::IdentifiedPlant& table) {
  std::ofstream fit(prefix + "-fit.csv");
  fit << "t_s,setpoint_m,measured_m,model_m\n";
  for (std::size_t k = 0; k < run.position_m.size(); ++k)
    fit << k * run.period_s << ',' << run.setpoint_m[k] << ',' << run.position_m[k] << ','
        << id.model_position_m[k] << '\n';
  std::ofstream bode(prefix + "-bode.csv");
  bode << "omega_rad_s,identified_db,identified_deg,table_db,table_deg\n";
  const auto response = [](const control::CylinderPlant& p, double w) {
    const std::complex<double> s(0.0, w);
    return p.gain / (s * (s * s + p.b1 * s + p.b0));
  };
  for (double lw = 0.0; lw <= 3.5; lw += 0.01) {
    const double w = std::pow(10.0, lw);
    const auto a = response(id.plant.plant(), w);
    const auto b = response(table.plant(), w);
    bode << w << ',' << 20 * std::log10(std::abs(a)) << ',' << std::arg(a) * 180 / M_PI - 360.0 * (std::arg(a) > 0)
         << ',' << 20 * std::log10(std::abs(b)) << ',' << std::arg(b) * 180 / M_PI - 360.0 * (std::arg(b) > 0)
         << '\n';
  }
  if (!fit || !bode) throw CLI::ValidationError("--plot-data", "cannot write " + prefix + "-fit.csv/-bode.csv");
}

// A run as the command line names it: FILE, or FILE@<load>kg with the external load on the rod.
struct RunArgument {
  std::string file;
  std::optional<double> load_kg;
  std::string name;  // FILE's base name with @<load>kg, the plant's name in the set
};

RunArgument parse_run_argument(const std::string& text) {
  RunArgument a{text, std::nullopt, text};
  const auto at = text.rfind('@');
  // A file whose own name has an '@' is taken as it is.
  if (at != std::string::npos && !std::ifstream(text)) {
    std::string load = text.substr(at + 1);
    if (load.size() > 2 && load.compare(load.size() - 2, 2, "kg") == 0) load.resize(load.size() - 2);
    const std::optional<double> kg = parse_number(load);
    if (!kg || !(*kg >= 0.0))
      throw CLI::ValidationError("RUN", "expected FILE or FILE@<load>kg with a load >= 0 (e.g. run.csv@3kg), got '" +
                                            text + "'");
    a.file = text.substr(0, at);
    a.load_kg = *kg;
  }
  if (!std::ifstream(a.file)) throw CLI::ValidationError("RUN", "cannot read " + a.file);
  const auto slash = a.file.rfind('/');
  a.name = (slash == std::string::npos ? a.file : a.file.substr(slash + 1));
  if (a.load_kg) a.name += "@" + control::format_setting(*a.load_kg) + "kg";
  return a;
}

control::identification::ClosedLoopRun read_run(const RunArgument& a) {
  std::ifstream file(a.file);
  try {
    return read_telemetry_run(file);
  } catch (const control::identification::RunRefused& e) {
    throw CLI::ValidationError("identify", a.file + ": run refused: " + e.what());
  }
}

nlohmann::ordered_json json(const control::identification::DirectionCapability& d) {
  return {{"max_speed_m_s", d.max_speed_m_s},
          {"max_acceleration_m_s2", d.max_acceleration_m_s2},
          {"speed_limit_m_s", d.speed_limit_m_s},
          {"acceleration_limit_m_s2", d.acceleration_limit_m_s2},
          {"speed_pump_limited", d.speed_pump_limited},
          {"acceleration_force_limited", d.acceleration_force_limited}};
}

void print_capability(const control::identification::AxisCapability& c, bool in_set) {
  std::printf("capability (margin %.0f %%)%s\n", 100 * c.margin, in_set ? ", worst over the runs" : "");
  const auto line = [&](const char* name, const control::identification::DirectionCapability& d) {
    std::printf("  %-8s speed %.3f m/s (%s), limit %.3f; acceleration %.2f m/s² (%s), limit %.2f", name,
                d.max_speed_m_s, d.speed_pump_limited ? "pump" : "valve", d.speed_limit_m_s, d.max_acceleration_m_s2,
                d.acceleration_force_limited ? "supply force" : "hydraulic mode", d.acceleration_limit_m_s2);
    if (in_set) std::printf("  [%s]", d.worst_run.c_str());
    std::printf("\n");
  };
  line("extend", c.extend);
  line("retract", c.retract);
}

struct Options {
  std::vector<std::string> runs;
  bool set = false;
  std::string out;
  bool json = false;
  std::string plot_data;
  double bore_m = sim::CylinderGeometry{}.bore_m;
  double rod_m = sim::CylinderGeometry{}.rod_m;
  control::identification::SupplyRating rating{};
};

control::identification::IdentifyOptions identify_options(const Options& o) {
  control::identification::IdentifyOptions options;
  const sim::CylinderGeometry geometry{.bore_m = o.bore_m, .rod_m = o.rod_m};
  options.hydraulics.piston_area_m2 = geometry.piston_area();
  options.hydraulics.area_ratio = geometry.area_ratio();
  return options;
}

void identify_one(const Options& o) {
  if (o.runs.size() != 1) throw CLI::ValidationError("identify", "one RUN, or --set with several");
  const RunArgument arg = parse_run_argument(o.runs.front());
  const control::identification::IdentifyOptions options = identify_options(o);
  const control::identification::ClosedLoopRun run = read_run(arg);
  Identification id;
  control::identification::AxisCapability capability;
  try {
    id = control::identification::identify_run(run, options);
    capability = control::identification::axis_capability(id, options.hydraulics.piston_area_m2,
                                                           options.hydraulics.area_ratio, o.rating);
  } catch (const control::identification::RunRefused& e) {
    throw CLI::ValidationError("identify", std::string("run refused: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("identify", e.what());
  }
  const control::IdentifiedPlant table = nearest_table_plant(id);
  if (!o.plot_data.empty()) write_plot_data(o.plot_data, run, id, table);
  if (o.json) {
    nlohmann::ordered_json j = {
        {"working_point_m", id.working_point_m}, {"duration_s", id.duration_s}, {"kp_per_m", id.kp_per_m},
        {"peak_opening", id.peak_opening},       {"b0", json(id.plant.b0)},     {"b1", json(id.plant.b1)},
        {"k01", json(id.plant.k01)},             {"k01_retracting", json(id.plant.k01_retracting)},
        {"delay_s", id.plant.delay_s},           {"mass_kg", json(id.motion.mass_kg)},
        {"sigma_n_s_per_m", json(id.motion.damping_n_s_per_m)},
        {"external_force_n", json(id.motion.external_force_n)},
        {"dry_friction_n", json(id.motion.dry_friction_n)},
        {"stiffness_n_per_m", json(id.hydraulics.stiffness_n_per_m)},
        {"fit_index", id.fit_index},             {"residual_lags_outside_99", id.residuals.outside},
        {"off_grid_samples", run.off_grid_samples},
        {"nearest_table_a3", {{"position_m", table.position_m()}, {"load_kg", table.load_kg}}},
        {"capability",
         {{"margin", capability.margin}, {"extend", json(capability.extend)}, {"retract", json(capability.retract)}}}};
    std::printf("%s\n", j.dump().c_str());
    return;
  }
  const auto line = [](const char* name, const Estimate& e, const char* unit) {
    std::printf("  %-16s %10.4g ± %-8.2g %s\n", name, e.value, e.std_dev, unit);
  };
  std::printf("run: %.1f s at %.1f mm, P gain %.1f m^-1, peak opening %.3f\n", id.duration_s,
              id.working_point_m * 1e3, id.kp_per_m, id.peak_opening);
  if (run.off_grid_samples > 0) {
    std::printf("  %zu of %zu loop periods were taken from the row nearest to them, a base tick or more away\n"
                "  (the host missed base periods, or a telemetry sample was lost)\n",
                run.off_grid_samples, run.position_m.size());
  }
  std::printf("plant Y/Xv = k01·b0 / (s(s² + b1 s + b0)), delay %.2f ms\n", id.plant.delay_s * 1e3);
  line("b0", id.plant.b0, "1/s²");
  line("b1", id.plant.b1, "1/s");
  line("k01 (extending)", id.plant.k01, "mm/s");
  line("k01 (retracting)", id.plant.k01_retracting, "mm/s");
  std::printf("motion (eq 34, %d windows)\n", id.motion.windows);
  line("m", id.motion.mass_kg, "kg");
  line("sigma", id.motion.damping_n_s_per_m, "N s/m");
  line("F_e", id.motion.external_force_n, "N");
  line("dry friction", id.motion.dry_friction_n, "N");
  line("stiffness k_h", id.hydraulics.stiffness_n_per_m, "N/m");
  std::printf("fit index (eq 39) %.1f %%; residual autocorrelation: %d of %zu lags outside the 99 %% band (±%.3f)\n",
              100 * id.fit_index, id.residuals.outside, id.residuals.autocorrelation.size(), id.residuals.band);
  std::printf("nearest Table A3 plant: %d mm, %d kg (b0 %.0f, b1 %.0f, k01 %.0f)\n", table.position_mm,
              table.load_kg, table.b0, table.b1, table.k01);
  print_capability(capability, false);
}

void identify_many(const Options& o) {
  if (o.out.empty()) throw CLI::ValidationError("--out", "--set needs --out FILE for the plant set");
  if (!o.plot_data.empty() || o.json) throw CLI::ValidationError("--set", "--plot-data and --json take one RUN");
  std::vector<control::identification::NamedRun> runs;
  for (const std::string& text : o.runs) {
    const RunArgument arg = parse_run_argument(text);
    if (!arg.load_kg)
      throw CLI::ValidationError("--set", "name the load of every run: " + text + "@<load>kg (e.g. " + text + "@3kg)");
    runs.push_back({arg.name, *arg.load_kg, read_run(arg)});
  }
  control::identification::SetIdentification s;
  try {
    s = control::identification::identify_set(runs, identify_options(o), o.rating);
  } catch (const control::identification::RunRefused& e) {
    throw CLI::ValidationError("identify", std::string("run refused: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("identify", e.what());
  }
  std::printf("%-28s %8s %6s %8s %7s %7s %7s %6s %7s\n", "plant", "pos[mm]", "load", "b0", "b1", "k01+", "k01-",
              "fit%", "eq49");
  for (std::size_t i = 0; i < s.set.plants.size(); ++i) {
    const control::PlantSetEntry& p = s.set.plants[i];
    std::printf("%-28s %8.1f %6g %8.0f %7.1f %7.1f %7.1f %6.1f %7.3f%s\n", p.name.c_str(), p.position_m * 1e3,
                p.load_kg, p.b0_per_s2.value, p.b1_per_s.value, p.k01_m_s.value * 1e3,
                p.k01_retracting_m_s.value * 1e3, 100 * p.fit_index, p.nominal_score,
                i == s.set.nominal ? "  nominal" : "");
  }
  print_capability(s.set.capability, true);
  std::ostringstream text;  // all or nothing: a set the writer refuses leaves no file behind
  try {
    plant_set::write_plant_set(text, s.set);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--out", o.out + ": " + e.what());
  }
  std::ofstream out(o.out);
  out << text.str();
  out.close();
  if (!out) throw CLI::ValidationError("--out", "cannot write " + o.out);
  std::printf("wrote %zu plants to %s (nominal: %s)\n", s.set.plants.size(), o.out.c_str(),
              s.set.plants[s.set.nominal].name.c_str());
}

}  // namespace

void add_identify_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "identify",
      "The cylinder's plant (b0, b1, k01; m, sigma, F_e) and the axis's capability from a closed-loop run under a P "
      "controller; with --set, a plant set from runs at several working points");
  cmd->add_option("RUN", o->runs,
                  "CSV of `hsactl record` at the loop rate, as FILE or FILE@<load>kg (the external load on the rod; "
                  "required with --set)")
      ->required();
  cmd->add_flag("--set", o->set,
                "identify every RUN, choose the nominal plant (Puglisi et al. 2015, eq 49) and write the plant set "
                "to --out (docs/plant-set.md)");
  cmd->add_option("--out", o->out, "the plant-set file --set writes");
  cmd->add_option("--bore", o->bore_m, "piston bore, m (the simulated rig's by default)")->capture_default_str();
  cmd->add_option("--rod", o->rod_m, "rod diameter, m")->capture_default_str();
  cmd->add_option("--supply-pressure", o->rating.supply_pressure_pa,
                  "the power unit's supply (relief) pressure, Pa, for the capability")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--pump-flow", o->rating.pump_flow_m3_per_s, "the pump's flow, m^3/s (5 L/min = 8.333e-5)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--margin", o->rating.margin, "share of the capability a motion profile may ask for, (0, 1]")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 1.0));
  cmd->add_flag("--json", o->json, "print one JSON object (one RUN)");
  cmd->add_option("--plot-data", o->plot_data,
                  "write PREFIX-fit.csv and PREFIX-bode.csv (tools/plot-experiments turns them into PNGs; one RUN)");
  cmd->callback([o] {
    if (o->set) identify_many(*o); else identify_one(*o);
  });
}

}  // namespace hsa::analyze
