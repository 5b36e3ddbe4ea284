// hsa-analyze tune: PI gains for the cylinder loop over a set of plants (Puglisi et al. 2015,
// section 4; the method is control/pi_tuning.hpp). Prints the proposal with the worst margins and
// the predicted step over the set, and writes it as a gains file that `hsactl gains --from FILE`
// sends to hsad (whose gate checks it again).
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "control/gain_gate.hpp"
#include "control/loop_analysis.hpp"
#include "control/pi_tuning.hpp"
#include "control/plant_table.hpp"
#include "plant_set/plant_set_file.hpp"
#include "tools/hsa_analyze/commands.hpp"

namespace hsa::analyze {
namespace {

// The plants: a plant-set file, or Table A3 (with the paper's uncertainty model).
control::GatePlantSet plants_from(const std::string& path) {
  if (path.empty()) return control::table_a3_plant_set();
  try {
    return control::gate_plant_set(plant_set::load_plant_set(path), path);
  } catch (const std::exception& e) {
    throw CLI::ValidationError("--plants", e.what());
  }
}

std::string label(const control::GatePlantSet& set, std::size_t i) { return control::plant_name(set.plants[i]); }

void write_gains_file(const std::string& path, const control::GainGate& gate, const control::Tuning& t) {
  const control::GatePlantSet& set = gate.plants;
  const control::MarginRequirements& limits = gate.min;
  std::ofstream out(path);
  if (!out) throw CLI::ValidationError("--out", "cannot write '" + path + "'");
  const control::SetPerformance& p = t.performance;
  char text[2048];
  std::snprintf(text, sizeof text,
                "# PI gains proposed by `hsa-analyze tune`; send them with `hsactl gains --from %s`.\n"
                "# hsad checks them against its own plant set before they reach the loop.\n"
                "kp = %.10g  # valve opening per metre of error (m^-1)\n"
                "ki = %.10g  # valve opening per metre-second (m^-1 s^-1)\n"
                "\n"
                "# What the tuning predicted over its plant set (linear models, Puglisi et al. 2015 eq 41).\n"
                "[prediction]\n"
                "plants = \"%s\"\n"
                "min_gain_margin_db = %.4g\n"
                "min_phase_margin_deg = %.4g\n"
                "worst_gain_margin_db = %.4g  # %s\n"
                "worst_phase_margin_deg = %.4g  # %s\n"
                "worst_overshoot_pct = %.4g  # %s\n"
                "worst_settling_s = %.4g  # %s\n"
                "worst_recovery_s = %.4g  # %s\n",
                path.c_str(), t.gains.kp, t.gains.ki, set.name.c_str(), limits.min_gain_margin_db,
                limits.min_phase_margin_deg, p.verdict.worst_gain_margin.margins.gain_margin_db,
                control::plant_name(p.verdict.worst_gain_margin.plant).c_str(),
                p.verdict.worst_phase_margin.margins.phase_margin_deg,
                control::plant_name(p.verdict.worst_phase_margin.plant).c_str(), p.worst_overshoot_pct,
                label(set, p.worst_overshoot_plant).c_str(), p.worst_settling_s, label(set, p.worst_settling_plant).c_str(),
                p.worst_recovery_s, label(set, p.worst_recovery_plant).c_str());
  out << text;
  if (!out.flush()) throw CLI::ValidationError("--out", "cannot write '" + path + "'");
}

struct Options {
  std::string plants;  // a plant-set file; empty: Table A3
  double min_gain_margin_db = control::kDefaultMinGainMarginDb;  // hsad's gate's defaults
  double min_phase_margin_deg = control::kDefaultMinPhaseMarginDeg;
  double kp = 85.0;
  double ki = 460.0;
  std::string out;
  bool json = false;
};

void run(const Options& o) {
  const control::GainGate gate{plants_from(o.plants),
                               {.min_gain_margin_db = o.min_gain_margin_db, .min_phase_margin_deg = o.min_phase_margin_deg}};
  const control::GatePlantSet& set = gate.plants;
  const control::PiGainsSi running{.kp = o.kp, .ki = o.ki};
  const std::optional<control::Tuning> tuned = control::tune_pi(gate, {}, running);
  if (!tuned) {
    const control::SearchBox box;
    throw CLI::ValidationError("tune", "no PI gains with kp in [" + std::to_string(box.kp_min) + ", " +
                                           std::to_string(box.kp_max) + "] m^-1 pass the gain gate on " + set.name +
                                           " (gain margin " + std::to_string(o.min_gain_margin_db) +
                                           " dB, phase margin " + std::to_string(o.min_phase_margin_deg) +
                                           " deg on every plant); lower the minimum margins");
  }
  const control::SetPerformance& p = tuned->performance;
  const control::SetPerformance before = control::evaluate_on_set(gate, running);
  if (!o.out.empty()) write_gains_file(o.out, gate, *tuned);

  const auto gm = [](const control::SetPerformance& s) { return s.verdict.worst_gain_margin; };
  const auto pm = [](const control::SetPerformance& s) { return s.verdict.worst_phase_margin; };
  if (o.json) {
    const auto figures = [&](const control::PiGainsSi& g, const control::SetPerformance& s) {
      nlohmann::ordered_json j{{"kp", g.kp},
                               {"ki", g.ki},
                               {"passes_gate", s.feasible()},
                               {"gate_refusal", s.verdict.refusal},
                               {"worst_gain_margin_db", gm(s).margins.gain_margin_db},
                               {"worst_gain_margin_plant", control::plant_name(gm(s).plant)},
                               {"worst_phase_margin_deg", pm(s).margins.phase_margin_deg},
                               {"worst_phase_margin_plant", control::plant_name(pm(s).plant)},
                               {"min_crossover_rad_s", s.min_crossover_rad_s},
                               {"worst_overshoot_pct", s.worst_overshoot_pct},
                               {"worst_settling_s", s.worst_settling_s},
                               {"worst_settling_plant", label(set, s.worst_settling_plant)},
                               {"worst_recovery_s", s.worst_recovery_s},
                               {"worst_recovery_plant", label(set, s.worst_recovery_plant)}};
      if (s.verdict.small_gain) j["small_gain_norm"] = s.verdict.small_gain->norm;
      return j;
    };
    const nlohmann::ordered_json j{{"plants", set.name},
                                   {"plant_count", set.plants.size()},
                                   {"min_gain_margin_db", o.min_gain_margin_db},
                                   {"min_phase_margin_deg", o.min_phase_margin_deg},
                                   {"objective", "worst of the 2 % step settling and the load-step recovery"},
                                   {"proposed", figures(tuned->gains, p)},
                                   {"running", figures(running, before)},
                                   {"candidates", tuned->candidates}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("PI gains over the %zu plants of %s: the shortest worst-case step settling and load recovery\n"
              "that pass hsad's gain gate (gain margin >= %.1f dB and phase margin >= %.1f deg on every plant%s)\n"
              "(%d candidates)\n",
              set.plants.size(), set.name.c_str(), o.min_gain_margin_db, o.min_phase_margin_deg,
              set.uncertainty ? ", small-gain test" : "", tuned->candidates);
  const auto row = [&](const char* what, const control::PiGainsSi& g, const control::SetPerformance& s) {
    std::printf("  %-9s kp %8.2f /m (%.4f /mm)  ki %8.2f /(m s) (%.4f /(mm s))%s\n", what, g.kp, g.kp * 1e-3, g.ki,
                g.ki * 1e-3, s.feasible() ? "" : "  (the gate refuses them)");
    std::printf("            gain margin %6.2f dB (%s), phase margin %6.2f deg (%s)\n", gm(s).margins.gain_margin_db,
                control::plant_name(gm(s).plant).c_str(), pm(s).margins.phase_margin_deg,
                control::plant_name(pm(s).plant).c_str());
    if (s.verdict.small_gain) std::printf("            small gain: ||W1 T0|| = %.3f (<= 1)\n", s.verdict.small_gain->norm);
    std::printf("            step: overshoot up to %.1f %% (%s), 2 %% settling up to %.3f s (%s)\n",
                s.worst_overshoot_pct, label(set, s.worst_overshoot_plant).c_str(), s.worst_settling_s,
                label(set, s.worst_settling_plant).c_str());
    std::printf("            after a load step: back within 2 %% of its peak in up to %.3f s (%s)\n",
                s.worst_recovery_s, label(set, s.worst_recovery_plant).c_str());
  };
  row("proposed", tuned->gains, p);
  row("running", running, before);
  if (!o.out.empty()) std::printf("written to %s: hsactl gains --from %s\n", o.out.c_str(), o.out.c_str());
}

}  // namespace

void add_tune_command(CLI::App& app) {
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "tune", "PI gains for the cylinder loop: the fastest settling that keeps the minimum margins on every plant");
  cmd->add_option("--plants", options->plants,
                  "a plant-set file from `hsa-analyze identify --set` (docs/plant-set.md); default: Table A3")
      ->check(CLI::ExistingFile);
  cmd->add_option("--min-gain-margin-db", options->min_gain_margin_db, "smallest gain margin on any plant (dB)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  cmd->add_option("--min-phase-margin-deg", options->min_phase_margin_deg, "smallest phase margin on any plant (deg)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 89.0));
  cmd->add_option("--kp", options->kp, "the gains running now, m^-1: the search starts from them and they are compared")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--ki", options->ki, "the running integral gain, m^-1 s^-1")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", options->out, "write the proposed gains to this file, for `hsactl gains --from FILE`");
  cmd->add_flag("--json", options->json, "print JSON");
  cmd->callback([options] { run(*options); });
}

}  // namespace hsa::analyze
