// `hsa-analyze identify RUN.csv`: the cylinder's plant at one working point from a closed-loop
// run recorded by `hsactl record` (Puglisi et al. 2015, section 3; the method is
// control/identification/identify_run.hpp). This file reads the file and prints.
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "control/identification/identify_run.hpp"
#include "control/plant_table.hpp"
#include "sim/cylinder_geometry.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"

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

}  // namespace

void add_identify_command(CLI::App& app) {
  struct Options {
    std::string run;
    bool json = false;
    std::string plot_data;
    double bore_m = sim::CylinderGeometry{}.bore_m;
    double rod_m = sim::CylinderGeometry{}.rod_m;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "identify", "The cylinder's plant (b0, b1, k01; m, sigma, F_e) from a closed-loop run under a P controller");
  cmd->add_option("RUN", o->run, "CSV of `hsactl record` at the loop rate")->required()->check(CLI::ExistingFile);
  cmd->add_option("--bore", o->bore_m, "piston bore, m (the simulated rig's by default)")->capture_default_str();
  cmd->add_option("--rod", o->rod_m, "rod diameter, m")->capture_default_str();
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->add_option("--plot-data", o->plot_data,
                  "write PREFIX-fit.csv and PREFIX-bode.csv (tools/plot-experiments turns them into PNGs)");
  cmd->callback([o] {
    std::ifstream file(o->run);
    control::identification::IdentifyOptions options;
    const sim::CylinderGeometry geometry{.bore_m = o->bore_m, .rod_m = o->rod_m};
    options.hydraulics.piston_area_m2 = geometry.piston_area();
    options.hydraulics.area_ratio = geometry.area_ratio();
    control::identification::ClosedLoopRun run;
    Identification id;
    try {
      run = read_telemetry_run(file);
      id = control::identification::identify_run(run, options);
    } catch (const control::identification::RunRefused& e) {
      throw CLI::ValidationError("identify", std::string("run refused: ") + e.what());
    }
    const control::IdentifiedPlant table = nearest_table_plant(id);
    if (!o->plot_data.empty()) write_plot_data(o->plot_data, run, id, table);
    if (o->json) {
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
          {"nearest_table_a3", {{"position_m", table.position_m()}, {"load_kg", table.load_kg}}}};
      std::printf("%s\n", j.dump().c_str());
      return;
    }
    const auto line = [](const char* name, const Estimate& e, const char* unit) {
      std::printf("  %-16s %10.4g ± %-8.2g %s\n", name, e.value, e.std_dev, unit);
    };
    std::printf("run: %.1f s at %.1f mm, P gain %.1f m^-1, peak opening %.3f\n", id.duration_s,
                id.working_point_m * 1e3, id.kp_per_m, id.peak_opening);
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
  });
}

}  // namespace hsa::analyze
