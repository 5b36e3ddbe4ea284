// The [axes.valve_law] table of hsad's configuration for a law identified_valve_law()
// (control/valve_law.hpp) sets from a valve fit (control/identification/valve_fit.hpp), as
// `hsa-analyze valve-law` prints it, and the rule that refuses a fit the law should not be built on.
//
// Only the steps hsad runs: spring-inverse, feedforward and model-inverse (eq 31 of Canuto et al.
// (2014) with the model-inverse feed-forward of the reference), and model-predictor, damped and
// time-optimal, which add the [axes.valve_law.model] table (the identified valve the model predictor
// runs on) and, for time-optimal, [axes.valve_law.time_optimal]; and predictive, the predictive law
// (control/valve_predictive.hpp) in eq 31's place, with its [axes.valve_law.predictive] table. The
// repetitive and learning steps are not offered: hsad has no settings for them yet.
//
// The trust rule (valve_fit_refusal), and why:
// - the fit index (Puglisi et al. eq 39) at least kMinFitIndex: the feed-forward inverts the fitted
//   model, so it is only as good as the share of the spool's motion the model explains. The
//   simulated records fit at 99.8 %; below 90 % the model misses a tenth of the motion, and the
//   feed-forward would push that error into the spool instead of removing it;
// - the current limit I_max known: either the record's command went above it (the measured current
//   then stays at I_max, eq 1) or the drive's datasheet figure is given. The law clamps to it and
//   sets the dither's ceiling from it; a guess would let the law ask for current the drive cannot give;
// - g, f0, ζ and τa each with a standard deviation (batch means over the record's parts) within
//   kMaxRelativeStdDev of its value: a larger spread means the parts of the record disagree (a
//   drifting valve, too little excitation), and the one fit is not the valve's.
#pragma once

#include <string>
#include <string_view>

#include "control/identification/valve_fit.hpp"
#include "control/valve_law.hpp"
#include "control/valve_predictive_design.hpp"

namespace hsa::analyze {

inline constexpr double kMinFitIndex = 0.90;
inline constexpr double kMaxRelativeStdDev = 0.05;

// The step that is not one of identified_valve_law()'s: design_valve_predictive() builds the
// predictive law from the fit itself (its friction band, the LVDT's bandwidth and the regulator's
// delay, which IdentifiedValve does not carry), choosing its settings on the fit's own model.
inline constexpr std::string_view kPredictiveStep = "predictive";

// The eq-31 step named on the command line: "spring-inverse", "feedforward", "model-inverse",
// "model-predictor", "damped" or "time-optimal" (kPredictiveStep is the caller's to recognise first).
// Throws std::invalid_argument for any other name, the daemon-less steps included.
[[nodiscard]] control::ValveLawStep daemon_valve_law_step(std::string_view name);

// Why the fit cannot set a law, with what to record instead; empty when it can. `current_max_a`:
// the drive's datasheet limit, 0 when not given.
[[nodiscard]] std::string valve_fit_refusal(const control::identification::ValveFit& fit, double current_max_a);

// The law for `step` from `valve`, at the daemon's base period: identified_valve_law() with the
// period set, checked by ValveLaw's constructor (std::invalid_argument when the preset's dither
// frequency is not 1/(2·n·T) at this period, and by ValveModelPredictor's when the identified delay
// is beyond its delay line at this period). A zero-width dead band turns the dither off, and with
// it its frequency (the daemon refuses a frequency without a dither). The time-optimal trigger
// d_on = g·I_max·ω0·T is taken at this period (identified_time_optimal): at the preset's 1e-4 s it
// is identified_valve_law's.
[[nodiscard]] control::ValveLawParams daemon_valve_law(const control::IdentifiedValve& valve,
                                                       control::ValveLawStep step, double base_period_s);

// The predictive step at the daemon's base period, and what it was built from.
struct DaemonPredictiveLaw {
  control::ValvePredictiveValve valve;    // predictive_valve(fit, current_max_a)
  double dither_frequency_hz = 0.0;       // the preset's, 0 without a dead band (the dither is off)
  control::ValvePredictiveDesign design;  // its settings chosen on the fit's model
  control::ValveLawParams law;            // the spring-inverse step's I_max and I0, the design's law
};

// design_valve_predictive(predictive_valve(fit, current_max_a), base_period_s, the spring-inverse
// step's dither frequency): the grid's settings scored on the fit's own simulation model (about 12 s).
// The spring-inverse step's I_max and I0 (daemon_valve_law) stay in [axes.valve_law]: I0 is the null
// command the safety chain holds the valve at. Throws std::invalid_argument for what ValveLaw or the
// design refuses at this period (the preset's dither frequency not 1/(2·n·T), a delay τ + δ beyond
// the delay line) and RunRefused as identified_valve() does.
[[nodiscard]] DaemonPredictiveLaw daemon_predictive_law(const control::identification::ValveFit& fit,
                                                        double current_max_a, double base_period_s);

// The [axes.valve_law] table, a comment line before each key saying where its value came from.
// Numbers are printed in their shortest form that reads back to the same double. `law` is
// daemon_valve_law(valve, step, …); `source` names the record in the heading comment.
[[nodiscard]] std::string valve_law_table(const control::identification::ValveFit& fit,
                                          const control::IdentifiedValve& valve, control::ValveLawStep step,
                                          const control::ValveLawParams& law, std::string_view source);

// The same for the predictive step: [axes.valve_law] with I_max and I0 only (hsad refuses eq 31's keys
// beside the predictive table), then [axes.valve_law.predictive] with every key: the identified
// valve with its spread where the fit has one, the settings the design chose with the model's peak
// residual, the others its defaults. Pasted into a configuration whose base tick is the design's period,
// hsad builds `p.design.law` from it, bit for bit.
[[nodiscard]] std::string predictive_law_table(const control::identification::ValveFit& fit,
                                               const DaemonPredictiveLaw& p, std::string_view source);

}  // namespace hsa::analyze
