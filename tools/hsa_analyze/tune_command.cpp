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
#include "control/plant_set.hpp"
#include "control/plant_table.hpp"
#include "plant_set/plant_set_file.hpp"
#include "tools/hsa_analyze/commands.hpp"

namespace hsa::analyze {
namespace {

struct PlantSetInput {
  std::string name;  // for the user: where the plants came from
  std::vector<control::CylinderPlant> plants;
  std::vector<std::string> labels;  // one per plant, as "<position_mm> mm / <load_kg> kg"
};

PlantSetInput plant_set_file(const std::string& path) {
  control::PlantSet file;
  try {
    file = plant_set::load_plant_set(path);
  } catch (const std::exception& e) {
    throw CLI::ValidationError("--plants", e.what());
  }
  PlantSetInput set{path, {}, {}};
  for (const auto& p : file.plants) {
    set.plants.push_back(p.plant());
    char label[96];
    std::snprintf(label, sizeof label, "%g kg / %g mm", p.load_kg, p.position_m * 1e3);
    set.labels.push_back(label);
  }
  return set;
}

PlantSetInput table_a3() {
  PlantSetInput set{"Table A3 (Puglisi et al. 2015)", {}, {}};
  for (const auto& row : control::kTableA3) {
    set.plants.push_back(row.plant());
    set.labels.push_back(std::to_string(row.load_kg) + " kg / " + std::to_string(row.position_mm) + " mm");
  }
  return set;
}

void write_gains_file(const std::string& path, const PlantSetInput& set, const control::Tuning& t,
                      const control::TuningLimits& limits) {
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
                limits.min_phase_margin_deg, p.worst_gain_margin_db, set.labels[p.worst_gain_margin_plant].c_str(),
                p.worst_phase_margin_deg, set.labels[p.worst_phase_margin_plant].c_str(), p.worst_overshoot_pct,
                set.labels[p.worst_overshoot_plant].c_str(), p.worst_settling_s,
                set.labels[p.worst_settling_plant].c_str(), p.worst_recovery_s,
                set.labels[p.worst_recovery_plant].c_str());
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
  const PlantSetInput set = o.plants.empty() ? table_a3() : plant_set_file(o.plants);
  const control::TuningLimits limits{.min_gain_margin_db = o.min_gain_margin_db,
                                     .min_phase_margin_deg = o.min_phase_margin_deg};
  const control::PiGainsSi running{.kp = o.kp, .ki = o.ki};
  const std::optional<control::Tuning> tuned = control::tune_pi(set.plants, limits, running);
  if (!tuned) {
    throw CLI::ValidationError("tune", "no PI gains with kp in [" + std::to_string(limits.kp_min) + ", " +
                                           std::to_string(limits.kp_max) + "] m^-1 meet gain margin " +
                                           std::to_string(o.min_gain_margin_db) + " dB and phase margin " +
                                           std::to_string(o.min_phase_margin_deg) + " deg on every plant of " +
                                           set.name + "; lower the minimum margins");
  }
  const control::SetPerformance& p = tuned->performance;
  const control::SetPerformance before = control::evaluate_on_set(set.plants, running, limits);
  if (!o.out.empty()) write_gains_file(o.out, set, *tuned, limits);

  if (o.json) {
    const auto figures = [&](const control::PiGainsSi& g, const control::SetPerformance& s) {
      return nlohmann::ordered_json{{"kp", g.kp},
                                    {"ki", g.ki},
                                    {"meets_margins", s.feasible},
                                    {"worst_gain_margin_db", s.worst_gain_margin_db},
                                    {"worst_gain_margin_plant", set.labels[s.worst_gain_margin_plant]},
                                    {"worst_phase_margin_deg", s.worst_phase_margin_deg},
                                    {"worst_phase_margin_plant", set.labels[s.worst_phase_margin_plant]},
                                    {"min_crossover_rad_s", s.min_crossover_rad_s},
                                    {"worst_overshoot_pct", s.worst_overshoot_pct},
                                    {"worst_settling_s", s.worst_settling_s},
                                    {"worst_settling_plant", set.labels[s.worst_settling_plant]},
                                    {"worst_recovery_s", s.worst_recovery_s},
                                    {"worst_recovery_plant", set.labels[s.worst_recovery_plant]}};
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
  std::printf("PI gains over %zu plants of %s: the shortest worst-case step settling and load recovery\nwith gain margin >= %.1f dB "
              "and phase margin >= %.1f deg on every plant (%d candidates)\n",
              set.plants.size(), set.name.c_str(), o.min_gain_margin_db, o.min_phase_margin_deg, tuned->candidates);
  const auto row = [&](const char* what, const control::PiGainsSi& g, const control::SetPerformance& s) {
    std::printf("  %-9s kp %8.2f /m (%.4f /mm)  ki %8.2f /(m s) (%.4f /(mm s))%s\n", what, g.kp, g.kp * 1e-3, g.ki,
                g.ki * 1e-3, s.feasible ? "" : "  (below the minimum margins)");
    std::printf("            gain margin %6.2f dB (%s), phase margin %6.2f deg (%s)\n", s.worst_gain_margin_db,
                set.labels[s.worst_gain_margin_plant].c_str(), s.worst_phase_margin_deg,
                set.labels[s.worst_phase_margin_plant].c_str());
    std::printf("            step: overshoot up to %.1f %% (%s), 2 %% settling up to %.3f s (%s)\n",
                s.worst_overshoot_pct, set.labels[s.worst_overshoot_plant].c_str(), s.worst_settling_s,
                set.labels[s.worst_settling_plant].c_str());
    std::printf("            after a load step: back within 2 %% of its peak in up to %.3f s (%s)\n",
                s.worst_recovery_s, set.labels[s.worst_recovery_plant].c_str());
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
