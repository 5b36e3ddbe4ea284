// hsa-analyze experiment: the papers' experiments on the simulated rig, in direct mode (servo-valve)
// or cascade mode (proportional valve under the valve loop), and Canuto et al.'s valve experiments.
// The runs themselves are in experiments.cpp; this file selects the cases and the PI's gains (the
// paper's, --kp/--ki, or a gains file from `hsa-analyze tune --out`), prints the metrics beside the
// step the linear loop predicts (step_prediction.hpp) and writes the --csv time series.
#include <algorithm>
#include <cmath>
#include <map>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "control/gain_gate.hpp"
#include "plant_set/plant_set_file.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/experiments.hpp"
#include "tools/hsa_analyze/step_prediction.hpp"
#include "tools/hsactl/gains_file.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"
#include "tools/hsa_analyze/valve_experiments.hpp"
#include "tools/hsa_analyze/valve_learning_curve.hpp"
#include "control/valve_learning_design.hpp"
#include "control/valve_predictive_design.hpp"
#include "tools/hsa_analyze/valve_file.hpp"
#include "tools/hsa_analyze/json_list.hpp"

namespace hsa::analyze {

namespace {

struct Options {
  std::string experiment;
  std::vector<double> positions;  // empty: the paper's cases
  std::vector<double> loads;
  bool json = false;
  Drive drive = Drive::direct;
  std::string csv;  // empty: no time series
  double load_change_s = kHandLoadChangeS;
  double integral_dead_band_m = kIntegralDeadBandM;
  // The PI's gains: the paper's (Setup's) unless --kp/--ki or --gains-from say otherwise.
  double kp = control::PiParams{}.kp;
  double ki = control::PiParams{}.ki;
  std::string gains_from;  // a gains file (`hsa-analyze tune --out`); empty: kp and ki above
  std::string plants;      // the set the step's prediction is read from; empty: Table A3
  bool csv_prediction = false;  // step: the predicted steps go into the --csv too
  ValveExcitation excitation;  // valve-excite
  std::string valve_law = "preset";  // valve: the law (ValveLawStep, or the preset)
  std::string valve_file;            // valve, valve-excite: the valve's file; empty: the paper's valve
  std::uint64_t rig_seed = 1;        // valve: the scored runs' rig noise
  sim::ProportionalValveParameters valve;  // read from valve_file
  Trace trace;

  // The experiments' PI with this run's gains and integral dead band; P-only passes ki = 0.
  [[nodiscard]] Setup setup(std::optional<double> ki_override = std::nullopt) {
    Setup s;
    s.drive = drive;
    s.pi.kp = kp;
    s.pi.ki = ki_override.value_or(ki);
    s.pi.integral_dead_band_m = integral_dead_band_m;
    s.trace = csv.empty() ? nullptr : &trace;
    return s;
  }
};

// The given value, or the paper's cases when the option was not given.
template <std::size_t N>
std::vector<double> or_all(const std::vector<double>& given, const double (&all)[N]) {
  return given.empty() ? std::vector<double>(all, all + N) : given;
}

// The plants the step's prediction is read from.
control::GatePlantSet prediction_plants(const std::string& path) {
  if (path.empty()) return control::table_a3_plant_set();
  try {
    return control::gate_plant_set(plant_set::load_plant_set(path), path);
  } catch (const std::exception& e) {
    throw CLI::ValidationError("--plants", e.what());
  }
}

// Puglisi et al. (2015)'s band for the step (docs/experiments.md): less overshoot
// than its floor is a better-damped step, not a miss, so only the ceiling and the settling count.
constexpr double kBandOvershootFloorPct = 10.0;
constexpr double kBandOvershootCeilingPct = 30.0;
constexpr double kBandSettlingS = 0.6;

// The step's size and how much of it --csv records (run_step's defaults).
constexpr double kStepM = 0.010;
constexpr double kStepRecordS = 3.0;

void step_experiment(Options& o) {
  const control::GatePlantSet plants = prediction_plants(o.plants);
  const control::PiGainsSi gains{.kp = o.kp, .ki = o.ki};
  std::vector<StepMetrics> cases;
  std::vector<StepPrediction> predicted;
  for (double position : or_all(o.positions, kStepPositionsM))
    for (double load : or_all(o.loads, kLoadsKg)) {
      cases.push_back(run_step(position, load, o.setup(), kStepM, kStepRecordS));
      predicted.push_back(predict_step(plants, position, load, gains));
      if (o.csv_prediction) {
        const control::IdentifiedPlant& plant = plants.plants[nearest_plant(plants, position, load)];
        const double period = control::PiParams{}.period_s;
        trace_predicted_step(o.trace, step_label(position, load) + "_predicted", position, kStepM, period,
                             control::step_response(plant.plant(), gains, period,
                                                    static_cast<int>(std::lround(kStepRecordS / period))));
      }
    }
  const StepSpread spread = step_spread(cases);
  const auto within_band = [](const StepMetrics& m) {
    return m.overshoot_pct <= kBandOvershootCeilingPct && m.settling_s <= kBandSettlingS && !m.oscillating;
  };
  if (o.json) {
    JsonList list;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const StepMetrics& m = cases[i];
      const StepPrediction& p = predicted[i];
      list.add({{"experiment", "step"}, {"position_m", m.position_m}, {"load_kg", m.load_kg}, {"step_m", m.step_m},
                {"overshoot_pct", m.overshoot_pct}, {"settling_s", m.settling_s},
                {"rest_peak_to_peak_m", m.rest_peak_to_peak_m}, {"rest_error_m", m.rest_error_m},
                {"oscillating", m.oscillating}, {"kp", o.kp}, {"ki", o.ki}, {"within_band", within_band(m)},
                {"predicted_plant", p.plant}, {"predicted_overshoot_pct", p.overshoot_pct},
                {"predicted_settling_s", p.settling_s}});
    }
    if (cases.size() > 1) {
      list.add({{"experiment", "step spread"}, {"overshoot_spread_pts", spread.overshoot_spread_pts},
                {"settling_spread", spread.settling_spread}});
    }
    list.close();
    return;
  }
  std::printf("step (paper Exp. 1), %s mode: 10 mm step after 1 s at the position, held %g s; integral dead band %g µm\n",
              drive_name(o.drive), kStepHoldS, o.integral_dead_band_m * 1e6);
  std::printf("PI kp %.4g /m, ki %.4g /(m s)%s; predicted: the linear loop on the nearest plant of %s\n", o.kp, o.ki,
              o.gains_from.empty() ? "" : (" from " + o.gains_from).c_str(), plants.name.c_str());
  std::printf("%8s %6s %10s %10s %14s %14s %11s %11s %10s  %s\n", "pos[mm]", "load", "overshoot", "settle 2%",
              "rest p-p[µm]", "rest err[µm]", "oscillation", "predicted", "settle", "plant");
  std::size_t in_band = 0;
  std::size_t below_floor = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const StepMetrics& m = cases[i];
    const StepPrediction& p = predicted[i];
    in_band += within_band(m) ? 1 : 0;
    below_floor += within_band(m) && m.overshoot_pct < kBandOvershootFloorPct ? 1 : 0;
    std::printf("%8.0f %4.0fkg %9.2f%% %9.3fs %14.1f %14.1f %11s %10.2f%% %9.3fs  %s\n", m.position_m * 1e3, m.load_kg,
                m.overshoot_pct, m.settling_s, m.rest_peak_to_peak_m * 1e6, m.rest_error_m * 1e6,
                m.oscillating ? "SUSTAINED" : "none", p.overshoot_pct, p.settling_s, p.plant.c_str());
  }
  std::printf("(rest: the last %g s of the hold; sustained above %g counts peak to peak)\n", kRestWindowS,
              kOscillationLimitCounts);
  std::printf("the paper's band (overshoot %g-%g %%, 2 %% settling <= %g s, no sustained oscillation): %zu of %zu cases"
              " within",
              kBandOvershootFloorPct, kBandOvershootCeilingPct, kBandSettlingS, in_band, cases.size());
  if (below_floor > 0) std::printf(", %zu of them with less overshoot than its floor (better damped)", below_floor);
  std::printf("\n");
  if (cases.size() > 1) {
    std::printf("spread over %zu cases: overshoot %.2f points (max - min), settling %.1f %% (max/min - 1)\n",
                cases.size(), spread.overshoot_spread_pts, spread.settling_spread * 100.0);
  }
}

void sine_experiment(Options& o, const std::vector<double>& omegas, int periods) {
  const std::vector<double> loads = or_all(o.loads, kLoadsKg);
  std::vector<SineMetrics> runs;
  for (double omega : omegas)
    for (double load : loads) runs.push_back(run_sine(omega, load, periods, o.setup()));
  if (o.json) {
    JsonList list;
    for (const SineMetrics& m : runs) {
      list.add({{"experiment", "sine"}, {"omega_rad_s", m.omega_rad_s}, {"load_kg", m.load_kg},
                {"periods", m.periods}, {"max_error_m", m.max_error_m}});
    }
    list.close();
    return;
  }
  std::printf("sine (paper Exp. 2), %s mode: 150 + 125 sin(wt) mm, %d periods; max |error| after the first period [mm]\n",
              drive_name(o.drive), periods);
  std::printf("%10s", "w[rad/s]");
  for (double load : loads) std::printf(" %8.0fkg", load);
  std::printf("\n");
  for (std::size_t i = 0; i < omegas.size(); ++i) {
    std::printf("%10g", omegas[i]);
    for (std::size_t j = 0; j < loads.size(); ++j) std::printf(" %10.3f", runs[i * loads.size() + j].max_error_m * 1e3);
    std::printf("\n");
  }
}

void disturbance_experiment(Options& o) {
  const double base = o.loads.empty() ? 0.0 : o.loads.front();
  const DisturbanceMetrics m = run_disturbance(base, 3.0, o.setup(), o.load_change_s);
  if (o.json) {
    JsonList list;
    list.add({{"experiment", "disturbance"}, {"base_load_kg", m.base_load_kg}, {"added_kg", m.added_kg},
              {"change_s", m.change_s}, {"add_s", m.add_s}, {"remove_s", m.remove_s},
              {"baseline_error_m", m.baseline_error_m}, {"added_peak_error_m", m.added_peak_error_m},
              {"removed_peak_error_m", m.removed_peak_error_m}, {"peak_error_m", m.peak_error_m},
              {"final_error_m", m.final_error_m}, {"stable", m.stable}});
    list.close();
    return;
  }
  std::printf("disturbance (paper Exp. 3), %s mode: 0.5 rad/s sine on %g kg, +%g kg at %.2f s, removed at %.2f s,"
              " each over %g s\n",
              drive_name(o.drive), m.base_load_kg, m.added_kg, m.add_s, m.remove_s, m.change_s);
  std::printf("  max |error| before the change  %.3f mm\n", m.baseline_error_m * 1e3);
  std::printf("  peak |error| with the load on  %.3f mm\n", m.added_peak_error_m * 1e3);
  std::printf("  peak |error| after removal     %.3f mm\n", m.removed_peak_error_m * 1e3);
  std::printf("  peak |error| (after period 1)  %.3f mm\n", m.peak_error_m * 1e3);
  std::printf("  max |error| over last period   %.3f mm  -> %s\n", m.final_error_m * 1e3,
              m.stable ? "stable" : "NOT back to its earlier tracking");
}

void p_only_experiment(Options& o) {
  std::vector<HoldMetrics> runs;
  for (double position : or_all(o.positions, kStepPositionsM)) {
    for (double load : or_all(o.loads, kLoadsKg)) {
      runs.push_back(run_hold(position, load, o.setup(0.0)));
      runs.push_back(run_hold(position, load, o.setup()));
    }
  }
  if (o.json) {
    JsonList list;
    for (const HoldMetrics& m : runs) {
      list.add({{"experiment", "p-only"}, {"position_m", m.position_m}, {"load_kg", m.load_kg}, {"kp", m.kp},
                {"ki", m.ki}, {"mean_error_m", m.mean_error_m}, {"max_abs_error_m", m.max_abs_error_m}});
    }
    list.close();
    return;
  }
  std::printf("p-only, %s mode: hold for 5 s; steady error over the last second [µm], P (Ki = 0) against PI\n", drive_name(o.drive));
  std::printf("%8s %6s %12s %12s %12s %12s\n", "pos[mm]", "load", "P mean", "P max|e|", "PI mean", "PI max|e|");
  for (std::size_t k = 0; k + 1 < runs.size(); k += 2) {
    const HoldMetrics& p = runs[k];
    const HoldMetrics& pi = runs[k + 1];
    std::printf("%8.0f %4.0fkg %12.1f %12.1f %12.1f %12.1f\n", p.position_m * 1e3, p.load_kg, p.mean_error_m * 1e6,
                p.max_abs_error_m * 1e6, pi.mean_error_m * 1e6, pi.max_abs_error_m * 1e6);
  }
  std::printf("(in this simulator the P error comes only from the valve's 0.3 L/min null leakage: see docs/experiments.md)\n");
}

// The valve law of --valve-law: the preset, or a step of docs/valve-loop.md set from the valve
// identified on a record of the simulated rig (valve-excite's defaults, fit_valve).
control::ValveLawParams valve_law_of(const std::string& name, const std::optional<control::IdentifiedValve>& valve,
                                     double reference_period_s) {
  if (name == "preset") return control::simulated_proportional_valve_law();
  if (name == "spring-inverse") return control::identified_valve_law(*valve, control::ValveLawStep::spring_inverse);
  if (name == "feedforward") return control::identified_valve_law(*valve, control::ValveLawStep::feedforward);
  if (name == "model-inverse") return control::identified_valve_law(*valve, control::ValveLawStep::model_inverse);
  if (name == "model-predictor") return control::identified_valve_law(*valve, control::ValveLawStep::model_predictor);
  if (name == "damped") return control::identified_valve_law(*valve, control::ValveLawStep::damped);
  if (name == "time-optimal") return control::identified_valve_law(*valve, control::ValveLawStep::time_optimal);
  if (name == "learning") return control::identified_valve_law(*valve, control::ValveLawStep::learning, reference_period_s);
  if (name == "predictive") return control::identified_valve_law(*valve, control::ValveLawStep::spring_inverse);
  return control::identified_valve_law(*valve, control::ValveLawStep::repetitive, reference_period_s);
}

// The learning step's design on the identified loop and its triangle residual period by period.
void print_valve_learning(const control::IdentifiedValve& valve, const control::ValveLawParams& law,
                          const sim::ProportionalValveParameters& plant) {
  const control::ValveLawParams loop = control::identified_valve_law(valve, control::ValveLawStep::model_inverse);
  const control::ValveLearningSettings st = control::valve_learning_settings();
  const control::ValveLearningDesign d = control::design_valve_learning(valve, loop, law.learning_period_samples, st);
  const std::vector<double> rho = control::valve_learning_convergence(valve, loop, d);
  std::printf("  learning (identified loop): N %d, D %d samples, f_Q %g Hz, k_L %g, M %d; convergence max|Q - H.G| %.3f"
              " (< 1 converges); at harmonics 1, 3, 5, 11, 21, 31: %.3f %.3f %.3f %.3f %.3f %.3f\n",
              d.period_samples, d.delay_samples, st.filter_hz, st.gain, static_cast<int>(d.filter.size() / 2),
              d.convergence, rho.at(1), rho.at(3), rho.at(5), rho.at(11), rho.at(21), rho.at(31));
  std::printf("  triangle after 2 + p periods:   p  delay[ms]  max[um]  rms[um]\n");
  const std::vector<ValveTriangleMetrics> curve = valve_learning_curve(law, plant, law.learning_settle_periods);
  for (std::size_t p = 0; p < curve.size(); ++p)
    std::printf("  %32zu %10.2f %8.1f %8.1f\n", p, curve[p].delay_s * 1e3, curve[p].residual_max_m * 1e6,
                curve[p].residual_rms_m * 1e6);
}

// The valve's name in the output: the file it came from, or the paper's.
std::string valve_name(const Options& o) { return o.valve_file.empty() ? "the paper's valve" : o.valve_file; }

void valve_experiment(Options& o) {
  Trace* trace = o.csv.empty() ? nullptr : &o.trace;
  // The identified laws know the valve only through the record valve-excite makes on it (with
  // --excite-* as given) and its fit.
  std::optional<control::IdentifiedValve> valve;
  std::optional<control::identification::ValveFit> fit;
  if (o.valve_law != "preset") {
    fit = control::identification::fit_valve(run_valve_excitation(o.excitation, o.valve));
    valve = control::identification::identified_valve(*fit);
  }
  // Every reference is periodic at 10 Hz except the sine sweep's, which gets its own period.
  control::ValveLawParams law = valve_law_of(o.valve_law, valve, 0.1);
  std::optional<control::ValvePredictiveDesign> predictive;
  if (o.valve_law == "predictive") {
    // The spring-inverse step's period, I_max and dither frequency, and the design's law in place of
    // its feedback.
    predictive = control::design_valve_predictive(control::predictive_valve(*fit), law.period_s, law.dither_frequency_hz);
    law.predictive = predictive->law;
  }
  const ValveTriangleMetrics tri = run_valve_triangle(0.70, 10.0, law, o.valve, trace, o.rig_seed);
  const ValveSquareMetrics sq = run_valve_square(0.50, 10.0, law, o.valve, trace, o.rig_seed);
  std::vector<ValveSineMetrics> sweep;
  for (double f : kValveSineFrequenciesHz) {
    // The trace keeps the 5 % sine at 10 and 100 Hz only: the sweep's other points add nothing a
    // plot needs.
    // The repetitive and learning steps need a period of whole samples: at 30, 70, … Hz they run without it.
    const double samples = 1.0 / (f * law.period_s);
    const bool whole = std::abs(samples - std::round(samples)) < 1e-6;
    const control::ValveLawParams sine_law = law.repetitive_period_samples == 0 && law.learning_period_samples == 0 ? law
                                             : whole ? valve_law_of(o.valve_law, valve, 1.0 / f)
                                                     : valve_law_of("model-inverse", valve, 0.0);
    sweep.push_back(run_valve_sine(0.05, f, sine_law, o.valve, f == 10.0 || f == 100.0 ? trace : nullptr, o.rig_seed));
  }
  const ValveSlewBound bound = valve_slew_bound(0.50, o.valve);
  const double bandwidth = minus_3db_frequency_hz(sweep);
  double worst_db = 0.0;  // largest |gain| up to 100 Hz
  for (const ValveSineMetrics& m : sweep)
    if (m.frequency_hz <= 100.0) worst_db = std::max(worst_db, std::abs(m.gain_db));
  if (o.json) {
    JsonList list;
    list.add({{"experiment", "valve triangle"}, {"law", o.valve_law}, {"valve", valve_name(o)}, {"seed", o.rig_seed}, {"stroke_pct", 70}, {"frequency_hz", 10}, {"delay_s", tri.delay_s},
              {"residual_max_m", tri.residual_max_m}, {"residual_rms_m", tri.residual_rms_m},
              {"repeating_max_m", tri.repeating_max_m}, {"repeating_rms_m", tri.repeating_rms_m},
              {"nonrepeating_max_m", tri.nonrepeating_max_m}, {"nonrepeating_rms_m", tri.nonrepeating_rms_m}});
    list.add({{"experiment", "valve square"}, {"stroke_pct", 50}, {"frequency_hz", 10},
              {"slew_rate_m_s", sq.slew_rate_m_s}, {"rise_10_90_s", sq.rise_10_90_s},
              {"overshoot_pct", sq.overshoot_pct}, {"settled_error_m", sq.settled_error_m},
              {"arrival_error_m", sq.arrival_error_m},
              {"slew_bound_m_s", bound.slew_rate_m_s}, {"rise_bound_up_s", bound.rise_up_s},
              {"rise_bound_down_s", bound.rise_down_s}});
    for (const ValveSineMetrics& m : sweep) {
      list.add({{"experiment", "valve sine"}, {"stroke_pct", 5}, {"frequency_hz", m.frequency_hz},
                {"gain_db", m.gain_db}, {"phase_deg", m.phase_deg}, {"delay_s", m.delay_s}});
    }
    list.add({{"experiment", "valve bandwidth"}, {"minus_3db_hz", bandwidth}, {"max_abs_gain_db_to_100hz", worst_db}});
    list.close();
    return;
  }
  std::printf("valve (Canuto et al. 2014, section 4): proportional valve under the valve loop at 10 kHz, LVDT measured\n");
  std::printf("  valve: %s; law: %s%s\n", valve_name(o).c_str(), o.valve_law.c_str(),
              o.valve_law == "preset" ? " (tuned on the paper's valve)"
                                      : ", from the valve identified on valve-excite's record");
  if (o.rig_seed != 1) std::printf("  the rig's noise drawn with seed %llu\n", static_cast<unsigned long long>(o.rig_seed));
  std::printf("  70 %% triangle, 10 Hz: delay %.2f ms (limit 5, paper 3); residual |eta| max %.1f um, rms %.1f um"
              " (eq 9; limit 10 um, paper < 40)\n",
              tri.delay_s * 1e3, tri.residual_max_m * 1e6, tri.residual_rms_m * 1e6);
  std::printf("                        over the 4 periods: repeating max %.1f um, rms %.1f um; period to period max %.1f um,"
              " rms %.1f um\n",
              tri.repeating_max_m * 1e6, tri.repeating_rms_m * 1e6, tri.nonrepeating_max_m * 1e6,
              tri.nonrepeating_rms_m * 1e6);
  std::printf("  50 %% square, 10 Hz: slew rate %.3f m/s (10-90 %%, %.2f ms; limit 0.25, paper 0.12), overshoot %.1f %%,"
              " settled |error| %.1f um\n",
              sq.slew_rate_m_s, sq.rise_10_90_s * 1e3, sq.overshoot_pct, sq.settled_error_m * 1e6);
  std::printf("                        after arrival (the first turn past 90 %%) |error| up to %.1f um\n",
              sq.arrival_error_m * 1e6);
  std::printf("  physics bound (full current from the step): slew %.3f m/s (10-90 %% %.2f ms up at I_max, %.2f ms down at 0)\n",
              bound.slew_rate_m_s, bound.rise_up_s * 1e3, bound.rise_down_s * 1e3);
  std::printf("  5 %% sine: %8s %9s %10s %9s\n", "f[Hz]", "gain[dB]", "phase[deg]", "delay[ms]");
  for (const ValveSineMetrics& m : sweep)
    std::printf("  %18g %9.2f %10.1f %9.2f\n", m.frequency_hz, m.gain_db, m.phase_deg, m.delay_s * 1e3);
  std::printf("  within +-%.2f dB up to 100 Hz (limit 3); -3 dB at %.0f Hz\n", worst_db, bandwidth);
  if (law.learning_period_samples > 0) print_valve_learning(*valve, law, o.valve);
  if (predictive) {
    const control::ValvePredictiveSettings& st = predictive->settings;
    std::printf("  predictive (chosen on the identified valve's model, %zu candidates): P %d samples, H %d, rho %g m^2/A^2,"
                " dither %.2f w (%.1f of it kept off the limits), disturbance walk %g A; %.1f um on that model\n",
                predictive->candidates.size(), st.preview_samples, st.preview_samples + st.horizon_extra_samples,
                st.rate_weight_m2_per_a2, st.dither_fraction, st.headroom_fraction, st.disturbance_walk_a,
                predictive->peak_m * 1e6);
  }
}

// The record `hsa-analyze identify-valve` fits, written to --csv (columns in valve_excitation.hpp).
void valve_excite_experiment(Options& o) {
  if (o.csv.empty()) throw CLI::ValidationError("valve-excite", "writes its record: give --csv FILE");
  const control::identification::ValveRecord r = run_valve_excitation(o.excitation, o.valve, 1, &o.trace);
  double low = r.spool_m.front(), high = r.spool_m.front();
  for (double x : r.spool_m) {
    low = std::min(low, x);
    high = std::max(high, x);
  }
  if (o.json) {
    JsonList list;
    list.add({{"experiment", "valve-excite"}, {"valve", valve_name(o)},
              {"samples", static_cast<double>(r.spool_m.size())},
              {"period_s", r.period_s}, {"bias_a", o.excitation.bias_a}, {"amplitude_a", o.excitation.amplitude_a},
              {"probe_a", o.excitation.probe_a}, {"spool_min_m", low}, {"spool_max_m", high}});
    list.close();
    return;
  }
  std::printf("valve-excite: %s, open loop at 10 kHz, PRMS %.3f ± %.3f A (%d levels, %g ms switching, "
              "holds of 1-%d) for %g s, then a probe to %g A\n",
              valve_name(o).c_str(), o.excitation.bias_a, o.excitation.amplitude_a, o.excitation.levels, o.excitation.switching_time_s * 1e3,
              o.excitation.max_hold_switches, o.excitation.duration_s, o.excitation.probe_a);
  std::printf("  %zu samples; spool (LVDT) from %.3f to %.3f mm\n", r.spool_m.size(), low * 1e3, high * 1e3);
  std::printf("  identify it with: hsa-analyze identify-valve %s\n", o.csv.c_str());
}

}  // namespace

void add_experiment_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto omegas = std::make_shared<std::vector<double>>();
  auto periods = std::make_shared<int>(2);
  CLI::App* cmd = app.add_subcommand(
      "experiment", "the papers' experiments on the simulated rig: PI at 1 kHz, valve loop and rig at 10 kHz");
  cmd->add_option("experiment", o->experiment, "step, sine, disturbance, p-only, valve or valve-excite (the record identify-valve fits)")
      ->required()
      ->check(CLI::IsMember({"step", "sine", "disturbance", "p-only", "valve", "valve-excite"}));
  cmd->add_option("--drive", o->drive,
                  "direct (servo-valve) or cascade (proportional valve under the valve loop); not for valve")
      ->transform(CLI::CheckedTransformer(std::map<std::string, Drive>{{"direct", Drive::direct},
                                                                       {"cascade", Drive::cascade}}));
  cmd->add_option("--csv", o->csv, "also write the time series of every run to this CSV file (tools/plot-experiments)");
  cmd->add_option("--position", o->positions, "rod position(s) in m (step, p-only); default 0.05, 0.15, 0.25")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 0.29));
  cmd->add_option("--load", o->loads, "load(s) in kg; default 0, 3, 6 (disturbance: base load, default 0)")
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--omega", *omegas, "sine: frequencies in rad/s; default 0.1 ... 10")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  cmd->add_option("--periods", *periods, "sine: periods to run (the first is not scored)")
      ->capture_default_str()
      ->check(CLI::Range(2, 100));
  cmd->add_option("--load-change", o->load_change_s,
                  "disturbance: seconds over which the weight goes on or comes off (0: a step)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--integral-dead-band", o->integral_dead_band_m,
                  "PI: the integrator holds while |error| is within this many m (0: the paper's bare PI, which "
                  "hunts in stick-slip)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  auto* kp = cmd->add_option("--kp", o->kp, "PI proportional gain, m^-1 (as `hsactl gains` and `hsa-analyze tune`)")
                 ->capture_default_str()
                 ->check(CLI::PositiveNumber);
  auto* ki = cmd->add_option("--ki", o->ki, "PI integral gain, m^-1 s^-1 (p-only: the PI's; its P has 0)")
                 ->capture_default_str()
                 ->check(CLI::NonNegativeNumber);
  cmd->add_option("--gains-from", o->gains_from, "take kp and ki from a gains file (`hsa-analyze tune --out FILE`)")
      ->check(CLI::ExistingFile)
      ->excludes(kp)
      ->excludes(ki);
  cmd->add_option("--plants", o->plants,
                  "step: predict each case on the nearest plant of this plant-set file (docs/plant-set.md); "
                  "default: Table A3")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--csv-prediction", o->csv_prediction,
                "step: also write each case's predicted step into --csv, as case <label>_predicted "
                "(tools/plot-commissioning-step)");
  cmd->add_option("--valve-law", o->valve_law,
                  "valve: the valve loop's law: preset (tuned on the simulator), or, from the valve identified on "
                  "valve-excite's record, spring-inverse, feedforward, model-inverse, model-predictor, damped, repetitive, "
                  "time-optimal, learning or predictive "
                  "(docs/valve-loop.md)")
      ->check(CLI::IsMember({"preset", "spring-inverse", "feedforward", "model-inverse", "model-predictor", "damped",
                             "repetitive", "time-optimal", "learning", "predictive"}));
  cmd->add_option("--valve", o->valve_file,
                  "valve, valve-excite: run on this valve instead of the paper's: a TOML file with a "
                  "[rig.proportional_valve] table, the sim plugin's keys (docs/valve-loop.md); the identified laws "
                  "identify it on valve-excite's record (--excite-*)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--excite-bias", o->excitation.bias_a,
                  "valve-excite, and valve's identified laws: the PRMS's centre current, A")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3.0));
  cmd->add_option("--excite-amplitude", o->excitation.amplitude_a,
                  "valve-excite, and valve's identified laws: the PRMS's amplitude, A")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 3.0));
  cmd->add_option("--excite-duration", o->excitation.duration_s,
                  "valve-excite, and valve's identified laws: the PRMS's duration, s")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 600.0));
  cmd->add_option("--excite-probe", o->excitation.probe_a,
                  "valve-excite, and valve's identified laws: the current the final probe ramps to, A, above the limit "
                  "to show it (0: no probe)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  auto* seed = cmd->add_option("--seed", o->rig_seed,
                               "valve: seed of the simulated rig's noise (LVDT, current regulator) in the scored runs; "
                               "another seed is another draw of the same experiment. The identified laws' record keeps "
                               "seed 1, so the law is the same for every seed")
                   ->capture_default_str()
                   ->check(CLI::Validator(
                       [](const std::string& v) {
                         return !v.empty() && v.size() <= 18 && v.find_first_not_of("0123456789") == std::string::npos
                                    ? std::string()
                                    : "expected a whole number from 0 to 10^18 - 1, got " + v;
                       },
                       "UINT"));
  cmd->add_flag("--json", o->json, "print a JSON list, one object per run");
  cmd->callback([o, omegas, periods, seed] {
    const std::string& e = o->experiment;
    if (!o->gains_from.empty()) {
      try {
        const ctl::GainsFromFile g = ctl::read_gains_file(o->gains_from);
        o->kp = g.kp;
        o->ki = g.ki;
      } catch (const std::exception& error) {
        throw CLI::ValidationError("--gains-from", error.what());
      }
    }
    if (!o->plants.empty() && e != "step") throw CLI::ValidationError("--plants", "applies to step only");
    if (o->csv_prediction && (e != "step" || o->csv.empty()))
      throw CLI::ValidationError("--csv-prediction", "applies to step, with --csv");
    if (!o->positions.empty() && (e == "sine" || e == "disturbance"))
      throw CLI::ValidationError("--position", "the sine is centred at 150 mm; --position applies to step and p-only");
    if (!omegas->empty() && e != "sine") throw CLI::ValidationError("--omega", "applies to sine only");
    if (e == "disturbance" && o->loads.size() > 1)
      throw CLI::ValidationError("--load", "disturbance takes one base load");
    if (e == "step") step_experiment(*o);
    if (e == "sine") {
      sine_experiment(*o, omegas->empty() ? or_all({}, kSineOmegasRadS) : *omegas, *periods);
    }
    if (e == "disturbance") disturbance_experiment(*o);
    if (e == "p-only") p_only_experiment(*o);
    if (seed->count() > 0 && e != "valve") throw CLI::ValidationError("--seed", "applies to valve only");
    if (!o->valve_file.empty() && e != "valve" && e != "valve-excite")
      throw CLI::ValidationError("--valve", "applies to valve and valve-excite only");
    if (e == "valve" || e == "valve-excite") {
      if (!o->valve_file.empty()) {
        try {
          o->valve = load_valve_file(o->valve_file);
        } catch (const std::exception& error) {
          throw CLI::ValidationError("--valve", error.what());
        }
      }
      if (!o->positions.empty() || !o->loads.empty())
        throw CLI::ValidationError(e, "runs the valve alone; --position and --load do not apply");
      if (o->kp != control::PiParams{}.kp || o->ki != control::PiParams{}.ki || !o->gains_from.empty())
        throw CLI::ValidationError(e, "runs the valve alone; the PI's gains do not apply");
      if (e == "valve") valve_experiment(*o); else valve_excite_experiment(*o);
    }
    if (!o->csv.empty()) {
      std::fflush(stdout);
      o->trace.write_csv(o->csv);
      std::fprintf(stderr, "wrote %zu rows to %s\n", o->trace.rows(), o->csv.c_str());
    }
  });
}

}  // namespace hsa::analyze
