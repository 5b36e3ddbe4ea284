#include "tools/hsa_analyze/valve_law_table.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "control/state_predictor.hpp"
#include "control/valve_model_predictor.hpp"
#include "control/valve_time_optimal.hpp"

namespace hsa::analyze {

using control::ValveLawParams;
using control::ValveLawStep;
using control::identification::Estimate;
using control::identification::ValveFit;

namespace {

// The shortest decimal that reads back as the same double, always a TOML float ("3.0", not "3").
std::string toml_number(double value) {
  char text[64];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
  if (ec != std::errc{}) throw std::logic_error("toml_number: cannot print");
  std::string s(text, end);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

// A figure for a comment: 5 significant digits.
std::string figure(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.5g", value);
  return text;
}

const char* step_name(ValveLawStep step) {
  switch (step) {
    case ValveLawStep::spring_inverse: return "spring-inverse";
    case ValveLawStep::feedforward: return "feedforward";
    case ValveLawStep::model_inverse: return "model-inverse";
    case ValveLawStep::model_predictor: return "model-predictor";
    case ValveLawStep::damped: return "damped";
    case ValveLawStep::time_optimal: return "time-optimal";
    default: return "?";
  }
}

struct Table {
  std::string text;
  void key(const char* name, double value, const std::string& why) {
    text += "# " + why + "\n" + name + " = " + toml_number(value) + "\n";
  }
};

// [axes.valve_law.model]: the identified valve the model predictor runs on (valve_model_predictor.hpp).
void model_table(Table& t, const ValveLawParams& p) {
  const control::ValveModelPredictorParams& m = p.model_predictor;
  const control::IdentifiedValve& v = m.valve;
  t.text += "# the identified valve the model predictor (control/valve_model_predictor.hpp) runs on, in the paper's "
            "predictor's place\n[axes.valve_law.model]\n";
  t.key("gain_m_per_a", v.gain_m_per_a, "g: identified (the spring's gain, eqs 1-2)");
  t.key("rest_position_m", v.rest_position_m, "X_min: identified (the spool at rest, no current)");
  t.key("natural_frequency_hz", v.natural_frequency_hz, "f0: identified (the spool's mode)");
  t.key("damping_ratio", v.damping_ratio, "zeta: identified");
  t.key("magnetic_lag_s", v.magnetic_lag_s, "tau_a: identified (the lag from current to force, eq 3)");
  t.key("dead_band_a", v.width_a, "w: identified (the magnetic play's width, eq 6)");
  t.key("delay_s", v.delay_s, "delay: identified (regulator and current-to-LVDT), " +
                                  figure(v.delay_s / p.period_s) + " base ticks");
  t.text += "# the model predictor's eigenvalues: Canuto et al. (2014) Table 2's halved (control/valve_law.cpp, "
            "identified_model_predictor)\npredictor_gamma = [";
  for (std::size_t i = 0; i < m.gamma.size(); ++i) t.text += (i ? ", " : "") + toml_number(m.gamma[i]);
  t.text += "]\n";
}

// [axes.valve_law.time_optimal]: the moves on a jump of the reference (valve_time_optimal.hpp), on the
// model above.
void time_optimal_table(Table& t, const control::IdentifiedValve& v, const ValveLawParams& p) {
  const control::ValveTimeOptimalParams& o = p.time_optimal;
  t.text += "# full-effort moves on a jump of the reference (control/valve_time_optimal.hpp), on the model "
            "above\n[axes.valve_law.time_optimal]\n";
  t.key("trigger_m", o.trigger_m,
        "d_on = g I_max w0 T: no spool of this valve moves that far in one " + figure(p.period_s * 1e6) +
            " us base tick (identified g, I_max = " + figure(v.current_max_a) + " A, f0 = " +
            figure(v.natural_frequency_hz) + " Hz)");
  t.key("margin_m", o.margin_m, "no margin: the model's spool lands on the target (control/valve_time_optimal.cpp)");
  t.text += "# the longest prediction, base ticks (control/valve_time_optimal.cpp)\nhorizon_samples = " +
            std::to_string(o.horizon_samples) + "\n";
}

std::string identified_g(const control::IdentifiedValve& v) {
  return "identified g = " + figure(v.gain_m_per_a * 1e3) + " mm/A";
}

// The heading (`what` its second line) and the keys every step prints: I_max and the null current I0.
Table head_table(const ValveFit& fit, const control::IdentifiedValve& v, const ValveLawParams& p, std::string_view step,
                 std::string_view source, std::string_view what) {
  Table t;
  t.text = "# hsa-analyze valve-law --step " + std::string(step) + " from " + std::string(source) + ": fit index " +
           figure(100.0 * fit.fit_index) + " %; for base_period_us = " + figure(p.period_s * 1e6) + "\n# (" +
           std::string(what) + ")\n";
  t.text += "[axes.valve_law]\n";
  t.key("max_current_a", p.max_current_a,
        fit.regulator.limit_reached ? "I_max: identified, the limit the record's current stayed at"
                                    : "I_max: the drive's datasheet figure (--current-max); the record never reached it");
  const bool clamped = p.bias_current_a != -v.rest_position_m / v.gain_m_per_a + 0.5 * v.width_a;
  t.key("bias_current_a", p.bias_current_a,
        "I0 = -X_min/g + w/2: identified X_min = " + figure(v.rest_position_m * 1e3) + " mm, " + identified_g(v) +
            ", w = " + figure(v.width_a) + " A" + (clamped ? " (clamped to [0, I_max])" : ""));
  return t;
}

constexpr std::string_view kKeepFullOpening =
    "# spool_at_full_opening_m: not identified (the spool travel the PI's opening of 1 asks for); keep the rig's\n";

}  // namespace

ValveLawStep daemon_valve_law_step(std::string_view name) {
  if (name == "spring-inverse") return ValveLawStep::spring_inverse;
  if (name == "feedforward") return ValveLawStep::feedforward;
  if (name == "model-inverse") return ValveLawStep::model_inverse;
  if (name == "model-predictor") return ValveLawStep::model_predictor;
  if (name == "damped") return ValveLawStep::damped;
  if (name == "time-optimal") return ValveLawStep::time_optimal;
  throw std::invalid_argument("expected spring-inverse, feedforward, model-inverse, model-predictor, damped, "
                              "time-optimal or predictive (hsad has no settings yet for the repetitive or learning "
                              "steps), got " +
                              std::string(name));
}

std::string valve_fit_refusal(const ValveFit& fit, double current_max_a) {
  std::string why;
  if (!(fit.fit_index >= kMinFitIndex)) {
    why += "the fit index (Puglisi et al. eq 39) is " + figure(100.0 * fit.fit_index) + " %, below " +
           figure(100.0 * kMinFitIndex) +
           " %: the model does not explain the spool's motion well enough to invert it; record again with the "
           "valve open loop, the bias holding the spool a little below mid-stroke and the amplitude moving it over "
           "most of its stroke (hsa-analyze experiment valve-excite --excite-bias/--excite-amplitude on the "
           "simulator, or the same sequence on the rig)\n";
  }
  if (!fit.regulator.limit_reached && !(current_max_a > 0.0)) {
    why += "the current limit I_max is unknown: the command never went above " + figure(fit.regulator.largest_command_a) +
           " A, so the measured current never stayed at the drive's limit; record with a probe above it "
           "(valve-excite's --excite-probe, default 3.5 A) or give the drive's datasheet limit with --current-max\n";
  }
  const struct {
    const char* name;
    const Estimate& e;
  } used[] = {{"g", fit.gain_m_per_a},
              {"f0", fit.natural_frequency_hz},
              {"zeta", fit.damping_ratio},
              {"tau_a", fit.magnetic_lag_s}};
  for (const auto& u : used) {
    if (!(u.e.std_dev <= kMaxRelativeStdDev * std::abs(u.e.value))) {
      why += std::string(u.name) + " = " + figure(u.e.value) + " ± " + figure(u.e.std_dev) + " scatters by more than " +
             figure(100.0 * kMaxRelativeStdDev) +
             " % over the record's parts: the parts disagree (a valve that drifts, or too little excitation); record "
             "a longer run (--excite-duration) with the valve warm\n";
    }
  }
  return why;
}

ValveLawParams daemon_valve_law(const control::IdentifiedValve& valve, ValveLawStep step, double base_period_s) {
  ValveLawParams p = control::identified_valve_law(valve, step);
  p.period_s = base_period_s;
  if (p.dither_amplitude_a == 0.0) p.dither_frequency_hz = 0.0;
  // d_on is a distance per base tick: at the daemon's period, not the preset's.
  if (p.time_optimal.enabled) p.time_optimal = control::identified_time_optimal(valve, base_period_s);
  const control::ValveLaw check(p);  // throws std::invalid_argument for what ValveLaw refuses
  // The model predictor is the cascade's, not the law's: its delay line must hold the delay at this period.
  if (p.model_predictor.enabled) const control::ValveModelPredictor predictor(p.model_predictor, base_period_s);
  return p;
}


std::string valve_law_table(const ValveFit& fit, const control::IdentifiedValve& v, ValveLawStep step,
                            const ValveLawParams& p, std::string_view source) {
  const std::string g = identified_g(v);
  const std::string preset = "preset feedback (tuned on the simulator, control/valve_law.cpp)";
  Table t = head_table(fit, v, p, step_name(step), source,
                       "Canuto et al. (2014) eq 31; control::identified_valve_law, docs/valve-loop.md");
  t.key("feedforward_a_per_m", p.feedforward_a_per_m, "K_r = 1/g: " + g);
  t.key("integral_a_per_m_s", p.integral_a_per_m_s, "K_i: " + preset);
  t.key("proportional_a_per_m", p.proportional_a_per_m, "k_p: " + preset);
  t.key("dead_band_compensation_a", p.dead_band_compensation_a, "dI: " + preset);
  t.key("dead_band_error_m", p.dead_band_error_m, "e_w: " + preset);
  const bool damped = step == ValveLawStep::damped || step == ValveLawStep::time_optimal;
  const ValveLawParams preset_law = control::simulated_proportional_valve_law();
  const std::string designed = ", the factor design_valve_feedback chose on the identified valve behind the model "
                               "predictor (control/valve_feedback_design.hpp)";
  t.key("velocity_a_per_m_s", p.velocity_a_per_m_s,
        damped ? "K_v = preset x " + figure(p.velocity_a_per_m_s / preset_law.velocity_a_per_m_s) + designed
               : "K_v: " + preset);
  t.key("acceleration_a_per_m_s2", p.acceleration_a_per_m_s2,
        damped ? "K_a = preset x " + figure(p.acceleration_a_per_m_s2 / preset_law.acceleration_a_per_m_s2) + designed
               : "K_a: " + preset);
  t.key("dither_amplitude_a", p.dither_amplitude_a,
        "dither = w (at most I_max/2): identified dead band w = " + figure(v.width_a) + " A");
  if (p.dither_amplitude_a > 0.0) t.key("dither_frequency_hz", p.dither_frequency_hz, "dither frequency: " + preset);
  if (step != ValveLawStep::spring_inverse) {
    const double w0 = 2.0 * std::numbers::pi * v.natural_frequency_hz;
    const double a1 = 2.0 * v.damping_ratio / w0 + v.magnetic_lag_s + v.delay_s;
    const std::string model = "identified f0 = " + figure(v.natural_frequency_hz) + " Hz, zeta = " +
                              figure(v.damping_ratio) + ", tau_a = " + figure(v.magnetic_lag_s * 1e3) + " ms";
    const bool inverse = step != ValveLawStep::feedforward;  // model-inverse and the steps on top of it
    t.key("reference_velocity_a_per_m_s", p.reference_velocity_a_per_m_s,
          std::string(inverse ? "K_rv = a1/g + K_v" : "K_rv = a1/g") + ", a1 = 2 zeta/w0 + tau_a + delay = " +
              figure(a1 * 1e3) + " ms: " + model + ", delay = " + figure(v.delay_s * 1e3) + " ms, " + g);
    if (inverse) {
      const double a2 = (1.0 + 2.0 * v.damping_ratio * w0 * v.magnetic_lag_s) / (w0 * w0);
      const double a3 = v.magnetic_lag_s / (w0 * w0);
      t.key("reference_acceleration_a_per_m_s2", p.reference_acceleration_a_per_m_s2,
            "K_ra = a2/g + K_a, a2 = (1 + 2 zeta w0 tau_a)/w0^2 = " + figure(a2) + " s^2: " + model + ", " + g);
      t.key("reference_jerk_a_per_m_s3", p.reference_jerk_a_per_m_s3,
            "K_rj = a3/g, a3 = tau_a/w0^2 = " + figure(a3) + " s^3: " + model + ", " + g);
    }
    t.key("reference_filter_hz", p.reference_filter_hz,
          std::string("f_r: chosen on the simulator for the ") + step_name(step) +
              " step (control/valve_law.cpp, docs/valve-loop.md)");
    if (inverse) {
      t.text += "# the loop tracks the filtered reference: the feedback corrects only the model's error\n";
      t.text += "track_filtered_reference = true\n";
    }
    t.key("direction_compensation_a", p.direction_compensation_a,
          "dI_d = 0: the dither moves the magnetic play every half period (control/valve_law.cpp)");
  }
  if (!p.model_predictor.enabled) {
    t.text += "# the state predictor's eigenvalues: Canuto et al. (2014) Table 2, which the preset feedback was tuned "
              "with\npredictor_gamma = [";
    for (std::size_t i = 0; i < control::kTable2Gamma.size(); ++i)
      t.text += (i ? ", " : "") + toml_number(control::kTable2Gamma[i]);
    t.text += "]\n";
  } else {
    t.text += "# no predictor_gamma: the model predictor of [axes.valve_law.model] runs in the paper's predictor's "
              "place\n";
  }
  t.text += kKeepFullOpening;
  if (p.model_predictor.enabled) model_table(t, p);
  if (p.time_optimal.enabled) time_optimal_table(t, v, p);
  return t.text;
}

DaemonPredictiveLaw daemon_predictive_law(const ValveFit& fit, double current_max_a, double base_period_s) {
  DaemonPredictiveLaw p;
  p.valve = control::predictive_valve(fit, current_max_a);
  const control::IdentifiedValve valve = control::identification::identified_valve(fit, current_max_a);
  // The spring-inverse step's I_max, I0 and dither frequency (the preset's, 0 with no dead band),
  // checked at this period.
  const ValveLawParams spring = daemon_valve_law(valve, ValveLawStep::spring_inverse, base_period_s);
  p.dither_frequency_hz = spring.dither_frequency_hz;
  p.design = control::design_valve_predictive(p.valve, base_period_s, p.dither_frequency_hz);
  p.law.period_s = base_period_s;
  p.law.max_current_a = spring.max_current_a;
  p.law.bias_current_a = spring.bias_current_a;
  p.law.predictive = p.design.law;
  return p;
}

namespace {

// "1.8237 +- 0.0012 mm/A": an identified figure with its standard deviation over the record's parts
// (batch means), times `scale` in `unit`.
std::string spread(double value, const Estimate& e, double scale, std::string_view unit) {
  return figure(value * scale) + " +- " + figure(e.std_dev * scale) + (unit.empty() ? "" : " ") + std::string(unit);
}

// The grid's values of one setting, "{16, 28}".
template <class T>
std::string grid_of(const std::vector<T>& values) {
  std::string text = "{";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + figure(static_cast<double>(values[i]));
  return text + "}";
}

}  // namespace

std::string predictive_law_table(const ValveFit& fit, const DaemonPredictiveLaw& p, std::string_view source) {
  const control::IdentifiedValve valve = control::identification::identified_valve(fit, p.valve.current_max_a);
  const control::identification::ValveModel& m = p.valve.model;
  const control::ValvePredictiveSettings& s = p.design.settings;
  const control::ValvePredictiveParams& law = p.design.law;
  const double T = p.law.period_s;
  const control::ValvePredictiveGrid grid;
  Table t = head_table(fit, valve, p.law, kPredictiveStep, source,
                       "the predictive law in Canuto et al. (2014) eq 31's place: control/valve_predictive.hpp, "
                       "docs/valve-loop.md");
  t.text += "# I0 stays the null command the safety chain holds the valve at. No eq 31 gains, dither, feed-forward or\n"
            "# predictor_gamma, no model or time_optimal table: the predictive law decides the current, and hsad\n"
            "# refuses them beside its table\n";
  t.text += kKeepFullOpening;
  const std::string identified = "identified, ";
  t.text += "# the identified valve (control/identification/valve_model.hpp) and the settings design_valve_predictive "
            "chose on the fit's own\n# simulation model: the least peak residual (eq 9) of the 70 % triangle at 10 Hz, " +
            figure(p.design.peak_m * 1e6) + " um, mean over the noise draws, of " +
            std::to_string(p.design.candidates.size()) + " settings\n[axes.valve_law.predictive]\n";
  t.key("gain_m_per_a", m.gain_m_per_a,
        "g: " + identified + spread(m.gain_m_per_a, fit.gain_m_per_a, 1e3, "mm/A") + " (the spring's gain, eqs 1-2)");
  t.key("rest_position_m", m.rest_position_m,
        "X_min: " + identified + spread(m.rest_position_m, fit.rest_position_m, 1e3, "mm") +
            " (the spool at rest, no current)");
  t.key("natural_frequency_hz", m.natural_frequency_hz,
        "f0: " + identified + spread(m.natural_frequency_hz, fit.natural_frequency_hz, 1.0, "Hz") + " (the spool's mode)");
  t.key("damping_ratio", m.damping_ratio, "zeta: " + identified + spread(m.damping_ratio, fit.damping_ratio, 1.0, ""));
  t.key("magnetic_lag_s", m.magnetic_lag_s,
        "tau_a: " + identified + spread(m.magnetic_lag_s, fit.magnetic_lag_s, 1e3, "ms") +
            " (the lag from current to force, eq 3)");
  t.key("dead_band_a", m.width_a,
        "w: " + identified + spread(m.width_a, fit.width_a, 1.0, "A") + " (the magnetic play's width, eq 6)");
  t.key("friction_band_m", m.friction_band_m,
        "s_f: " + identified + spread(m.friction_band_m, fit.friction_band_m, 1e6, "um") +
            " (the band dry friction holds the spool in, eqs 2 and 4)");
  t.key("delay_s", m.delay_s,
        "delta: identified, " + figure(m.delay_s * 1e3) +
            " ms from the current to the LVDT (the fit searches it on a grid of quarter samples: no spread)");
  t.key("sensor_bandwidth_hz", m.sensor_bandwidth_hz,
        "the LVDT's bandwidth (eq 7): the datasheet figure the fit assumed (--sensor-bandwidth), not identified");
  t.key("regulator_delay_s", p.valve.regulator_delay_s,
        "tau: identified, the current regulator's delay (eq 1), " + figure(p.valve.regulator_delay_s / T) +
            " base ticks; with delta the law's delay line holds D = round((tau + delta)/T) - 1 = " +
            std::to_string(law.delay_samples) + " commands");
  t.key("lvdt_noise_m", p.valve.lvdt_noise_m,
        "the LVDT reading's rms noise: a datasheet figure (the fit does not give it; "
        "control/valve_predictive_design.hpp)");
  const std::string chosen = "chosen by the design from ";
  t.text += "# P: " + chosen + grid_of(grid.preview_samples) + ", " + figure(s.preview_samples * T * 1e3) +
            " ms of the reference read ahead of the reading's target\npreview_samples = " +
            std::to_string(s.preview_samples) + "\n";
  t.text += "# H - P: the design's default (control/valve_predictive_design.hpp), not on its grid; the cost-to-go "
            "covers the rest\nhorizon_extra_samples = " +
            std::to_string(s.horizon_extra_samples) + "\n";
  t.key("rate_weight_m2_per_a2", s.rate_weight_m2_per_a2,
        "rho: " + chosen + grid_of(grid.rate_weights_m2_per_a2) + ", the price of a change of the command");
  t.key("dither_fraction", s.dither_fraction,
        "the dither's share of w: " + chosen + grid_of(grid.dither_fractions) + ", " +
            figure(law.dither_amplitude_a) + " A");
  if (law.dither_amplitude_a > 0.0) {
    t.key("dither_frequency_hz", p.dither_frequency_hz,
          "the dither's frequency: the preset's (control/valve_law.cpp), " +
              std::to_string(law.dither_half_period_samples) + " base ticks a half period");
  } else {
    t.text += "# no dither_frequency_hz: the identified dead band is 0, and with it the dither\n";
  }
  t.key("headroom_fraction", s.headroom_fraction,
        "the share of the dither the commands' box keeps off 0 and I_max: " + chosen +
            grid_of(grid.headroom_fractions) + ", the box [" + figure(law.lower_a) + ", " + figure(law.upper_a) +
            "] A");
  t.key("disturbance_walk_a", s.disturbance_walk_a,
        "the input disturbance's random walk a sample (the Kalman gain's): " + chosen +
            grid_of(grid.disturbance_walks_a));
  t.key("held_disturbance_walk_a", s.held_disturbance_walk_a,
        "the same while the target is held (a cascade at rest): the design's default, not on its grid (its triangle "
        "never holds; docs/valve-loop.md, \"In the cascade\")");
  t.key("velocity_walk_m_s", s.velocity_walk_m_s,
        "the spool velocity's random walk a sample (the Kalman gain's): the design's default, not on its grid");
  t.key("direction_velocity_m_s", s.direction_velocity_m_s,
        "v_d of the friction's sign tanh(target slope/v_d): the design's default, not on its grid");
  t.text += "# the QP's iterations a tick, after which its commands are clamped to the box: the design's default\n"
            "max_qp_iterations = " +
            std::to_string(s.max_qp_iterations) + "\n";
  return t.text;
}

}  // namespace hsa::analyze
