// `hsa-analyze valve-law RUN.csv --step spring-inverse|feedforward|model-inverse|model-predictor|damped|
// time-optimal|predictive`: the valve loop's law (Canuto et al. 2014, eq 31, with the model-inverse
// feed-forward of control/valve_law.hpp, the model predictor and the time-optimal moves; or the
// predictive law in eq 31's place, designed on the fit's own model) set
// from the valve identified on an open-loop record (the fit of `hsa-analyze identify-valve`,
// control/identification/valve_fit.hpp), printed as an [axes.valve_law] table to paste into hsad's
// configuration. A fit that is not trustworthy is refused (tools/hsa_analyze/valve_law_table.hpp
// says which and why). This file reads the file and prints.
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "control/identification/identify_run.hpp"
#include "control/identification/valve_fit.hpp"
#include "control/setting_range.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/valve_law_table.hpp"
#include "tools/hsa_analyze/valve_record.hpp"

namespace hsa::analyze {
namespace {

struct Options {
  std::string run;
  std::string step;
  double base_period_s = 1e-4;  // hsad's default base_period_us = 100
  double current_max_a = 0.0;
  control::identification::ValveFitOptions fit{};
};

void valve_law(const Options& o) {
  const bool predictive = o.step == kPredictiveStep;
  control::ValveLawStep step{};
  try {
    if (!predictive) step = daemon_valve_law_step(o.step);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--step", e.what());
  }
  std::ifstream file(o.run);
  if (!file) throw CLI::ValidationError("RUN", "cannot read " + o.run);
  control::identification::ValveFit fit;
  try {
    fit = control::identification::fit_valve(read_valve_record(file), o.fit);
  } catch (const control::identification::RunRefused& e) {
    throw CLI::ValidationError("valve-law", o.run + ": record refused: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("valve-law", o.run + ": " + e.what());
  }
  const std::string refusal = valve_fit_refusal(fit, o.current_max_a);
  if (!refusal.empty()) throw CLI::ValidationError("valve-law", o.run + ": no law from this fit:\n" + refusal);
  const auto at_this_period = [&](const std::invalid_argument& e) {
    return CLI::ValidationError("valve-law", std::string("the law does not fit a base period of ") +
                                                 control::format_setting(o.base_period_s) + " s: " + e.what());
  };
  if (predictive) {
    DaemonPredictiveLaw law;
    try {
      law = daemon_predictive_law(fit, o.current_max_a, o.base_period_s);
    } catch (const std::invalid_argument& e) {
      throw at_this_period(e);
    }
    std::fputs(predictive_law_table(fit, law, o.run).c_str(), stdout);
    return;
  }
  const control::IdentifiedValve valve = control::identification::identified_valve(fit, o.current_max_a);
  control::ValveLawParams law;
  try {
    law = daemon_valve_law(valve, step, o.base_period_s);
  } catch (const std::invalid_argument& e) {
    throw at_this_period(e);
  }
  std::fputs(valve_law_table(fit, valve, step, law, o.run).c_str(), stdout);
}

}  // namespace

void add_valve_law_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "valve-law",
      "The valve loop's law (Canuto et al. 2014, eq 31, the model-inverse feed-forward, the model predictor and "
      "the time-optimal moves, or the predictive law in eq 31's place) set from the valve identified on an "
      "open-loop record, printed as an [axes.valve_law] table (and its model, time_optimal or predictive "
      "sub-table) for hsad's configuration");
  cmd->add_option("RUN", o->run,
                  "CSV with columns t_s, command_a, current_a, spool_m, one row per valve period (hsa-analyze "
                  "experiment valve-excite --csv)")
      ->required();
  cmd->add_option("--step", o->step,
                  "spring-inverse (eq 31 from the identified spring, bias, limit and dead band), feedforward (+ the "
                  "reference's velocity through the model), model-inverse (the whole inverse, the loop tracking "
                  "the filtered reference), model-predictor (model-inverse behind the predictor driven by the "
                  "identified model: adds [axes.valve_law.model]), damped (model-predictor with K_v, K_a chosen on "
                  "the identified model), time-optimal (damped + full-effort moves on a jump of the reference: "
                  "adds [axes.valve_law.time_optimal]) or predictive (model-predictive control with preview in eq "
                  "31's place, its settings chosen on the fit's own model, about 8 s: [axes.valve_law.predictive])")
      ->required();
  cmd->add_option("--base-period", o->base_period_s,
                  "hsad's base period, s (base_period_us / 1e6): the valve loop's; the law is checked at it")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--current-max", o->current_max_a,
                  "the drive's current limit I_max, A (its datasheet's), when the record never reached it")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--sensor-bandwidth", o->fit.sensor_bandwidth_hz, "the LVDT's bandwidth, Hz (its datasheet's)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->callback([o] { valve_law(*o); });
}

}  // namespace hsa::analyze
