// `hsa-analyze identify-valve RUN.csv`: the proportional valve's model (Canuto et al. 2014,
// section 2, eqs 1–7) from an open-loop record at the valve rate (the method is
// control/identification/valve_fit.hpp; `hsa-analyze experiment valve-excite --csv` makes such a
// record on the simulated rig). Prints every parameter with its standard deviation beside the
// paper's (the simulator's) value, and the fit index. This file reads the file and prints.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "control/identification/identify_run.hpp"
#include "control/identification/valve_fit.hpp"
#include "sim/proportional_valve.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/valve_record.hpp"

namespace hsa::analyze {
namespace {

using control::identification::Estimate;

struct Options {
  std::string run;
  bool json = false;
  control::identification::ValveFitOptions fit{};
};

struct Line {
  const char* key;
  const char* name;
  Estimate value;
  double paper;
  const char* unit;
  double scale;  // printed in unit: value × scale
};

void identify_valve(const Options& o) {
  std::ifstream file(o.run);
  if (!file) throw CLI::ValidationError("RUN", "cannot read " + o.run);
  control::identification::ValveFit f;
  control::identification::ValveRecord record;
  try {
    record = read_valve_record(file);
    f = control::identification::fit_valve(record, o.fit);
  } catch (const control::identification::RunRefused& e) {
    throw CLI::ValidationError("identify-valve", o.run + ": record refused: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("identify-valve", o.run + ": " + e.what());
  }
  const sim::ProportionalValveParameters paper{};
  const double omega = 2.0 * std::numbers::pi * paper.natural_frequency_hz;
  const double k = paper.moving_mass_kg * omega * omega;
  const Line lines[] = {
      {"width_a", "dead band w", f.width_a, paper.hysteresis_width_a, "A", 1.0},
      {"magnetic_lag_s", "lag tau_a", f.magnetic_lag_s, paper.magnetic_lag_s, "ms", 1e3},
      {"natural_frequency_hz", "f0", f.natural_frequency_hz, paper.natural_frequency_hz, "Hz", 1.0},
      {"damping_ratio", "zeta", f.damping_ratio, paper.damping_ratio, "", 1.0},
      {"gain_m_per_a", "g = K_f/K", f.gain_m_per_a, paper.force_constant_n_per_a / k, "mm/A", 1e3},
      {"rest_position_m", "X_min (rest)", f.rest_position_m, paper.stroke_min_m, "mm", 1e3},
      {"friction_band_m", "s_f = F_c/K", f.friction_band_m, paper.coulomb_friction_n / k, "um", 1e6},
      {"stiffness_n_per_m", "K (for m)", f.stiffness_n_per_m, k, "N/m", 1.0},
      {"damping_n_s_per_m", "b (for m)", f.damping_n_s_per_m, 2.0 * paper.damping_ratio * paper.moving_mass_kg * omega,
       "N s/m", 1.0},
      {"force_constant_n_per_a", "K_f (for m)", f.force_constant_n_per_a, paper.force_constant_n_per_a, "N/A", 1.0},
      {"friction_n", "F_c (for m)", f.friction_n, paper.coulomb_friction_n, "N", 1.0},
  };
  const auto json = [](const Estimate& e) { return nlohmann::ordered_json{{"value", e.value}, {"std_dev", e.std_dev}}; };
  if (o.json) {
    nlohmann::ordered_json j;
    j["regulator"] = {{"delay_s", f.regulator.delay_s},
                      {"error_rms_a", f.regulator.error_rms_a},
                      {"error_max_a", f.regulator.error_max_a},
                      {"limit_reached", f.regulator.limit_reached},
                      {"largest_command_a", f.regulator.largest_command_a}};
    if (f.regulator.limit_reached) j["regulator"]["current_max_a"] = json(f.regulator.current_max_a);
    j["assumed_mass_kg"] = o.fit.assumed_mass_kg;
    for (const Line& l : lines) j[l.key] = json(l.value);
    j["end_stop_reached"] = f.end_stop_reached;
    if (f.end_stop_reached) j["stroke_max_m"] = json(f.stroke_max_m);
    j["delay_s"] = f.delay_s;
    j["sensor_bandwidth_hz"] = o.fit.sensor_bandwidth_hz;  // given, not fitted: the model's LVDT (eq 7)
    j["fit_index"] = f.fit_index;
    j["residual_lags_outside_99"] = f.residuals.outside;
    std::printf("%s\n", j.dump().c_str());
    return;
  }
  std::printf("proportional valve (Canuto et al. 2014, eqs 1-7) from %s\n", o.run.c_str());
  std::printf("%-16s %12s   %-10s %12s  %s\n", "parameter", "identified", "std dev", "paper", "unit");
  const auto row = [](const char* name, const Estimate& e, double paper, const char* unit, double scale) {
    std::printf("%-16s %12.5g ± %-10.2g %12.5g  %s\n", name, e.value * scale, e.std_dev * scale, paper * scale, unit);
  };
  std::printf("current regulator (eq 1): delay %.2f ms (paper %.2f), error rms %.2f mA, max %.2f mA (paper <= %.1f)\n",
              f.regulator.delay_s * 1e3, paper.current_delay_s * 1e3, f.regulator.error_rms_a * 1e3,
              f.regulator.error_max_a * 1e3, paper.current_error_max_a * 1e3);
  if (f.regulator.limit_reached)
    row("I_max", f.regulator.current_max_a, paper.current_max_a, "A", 1.0);
  else
    std::printf("%-16s not reached: the command never went above %.3f A\n", "I_max", f.regulator.largest_command_a);
  std::printf("dead band, magnetic lag (eq 6); spool (eqs 2, 3), ratios to the moving mass:\n");
  for (int i = 0; i < 7; ++i) row(lines[i].name, lines[i].value, lines[i].paper, lines[i].unit, lines[i].scale);
  if (f.end_stop_reached)
    row("X_max (stop)", f.stroke_max_m, paper.stroke_max_m, "mm", 1e3);
  else
    std::printf("%-16s not reached: the spool never rested at its highest reading\n", "X_max (stop)");
  std::printf("forces for an assumed moving mass m = %g kg (m is not identifiable: they scale with it):\n",
              o.fit.assumed_mass_kg);
  for (int i = 7; i < 11; ++i) row(lines[i].name, lines[i].value, lines[i].paper, lines[i].unit, lines[i].scale);
  std::printf("delay current -> LVDT %.3f ms (sampling and anti-aliasing); LVDT bandwidth %g Hz (given)\n",
              f.delay_s * 1e3, o.fit.sensor_bandwidth_hz);
  std::printf("fit index (Puglisi et al. eq 39) %.2f %%; residual autocorrelation: %d of %zu lags outside the 99 %% "
              "band (±%.3f)\n",
              100.0 * f.fit_index, f.residuals.outside, f.residuals.autocorrelation.size(), f.residuals.band);
}

}  // namespace

void add_identify_valve_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "identify-valve",
      "The proportional valve's model (dead band, magnetic lag, spool f0/zeta/gain, friction, stops, current "
      "regulator; Canuto et al. 2014, eqs 1-7) from an open-loop record at the valve rate");
  cmd->add_option("RUN", o->run,
                  "CSV with columns t_s, command_a, current_a, spool_m, one row per valve period (hsa-analyze "
                  "experiment valve-excite --csv)")
      ->required();
  cmd->add_option("--sensor-bandwidth", o->fit.sensor_bandwidth_hz, "the LVDT's bandwidth, Hz (its datasheet's)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--mass", o->fit.assumed_mass_kg,
                  "the moving mass assumed for K, b, K_f and F_c, kg (not identifiable from the record)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o] { identify_valve(*o); });
}

}  // namespace hsa::analyze
