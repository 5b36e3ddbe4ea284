#include "control/laws/proportional_cascade/proportional_cascade_law.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <stdexcept>
#include <utility>

#include "control/valve_predictive.hpp"

namespace hsa::control {

namespace {

// A whole number of samples in [min, max]; `why` says what counts them.
int whole_number(const LawSettings& t, std::string_view key, int min, int max, const std::string& why) {
  const double value = t.number(key, SettingRange::closed(min, max));
  if (value != std::floor(value)) {
    t.fail(key, "a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "] (" + why + ")");
  }
  return static_cast<int>(value);
}

// A dither's frequency: a square wave of whole base ticks, so the half period must be n·T.
double dither_frequency(const LawSettings& t, std::string_view key, double period_s) {
  const double hz = t.number(key, SettingRange::positive());
  const double half_period_ticks = 0.5 / (hz * period_s);
  if (!(half_period_ticks >= 1.0 && std::abs(half_period_ticks - std::round(half_period_ticks)) < 1e-6)) {
    char expected[160];
    std::snprintf(expected, sizeof expected,
                  "a frequency whose half period is a whole number of %g s base ticks (%g Hz, %g Hz, %g Hz, ...)",
                  period_s, 0.5 / period_s, 0.25 / period_s, 0.5 / (3 * period_s));
    t.fail(key, expected);
  }
  return hz;
}

// The model-inverse feed-forward of the reference (control/valve_law.hpp; identified_valve_law's
// feedforward and model_inverse steps, which `hsa-analyze valve-law` prints as this table). Every
// term rides on the state-variable filter at f_r, so without reference_filter_hz a gain on ṙ, r̈ or
// r⃛, the direction term or tracking the filtered reference would do nothing: refused, as a
// dither frequency without a dither is, rather than left to look configured.
void read_model_inverse(const LawSettings& t, ValveLawParams& v) {
  const SettingRange gain = SettingRange::closed(0.0, valve_law_bounds::kMaxGain);
  if (t.has("reference_filter_hz")) {
    v.reference_filter_hz = t.number("reference_filter_hz", SettingRange::positive());
    // ValveLaw's explicit filter update needs ω_r·T well below 1: at most 0.05/T, a tenth of the
    // base tick's Nyquist frequency.
    const double max_hz = kMaxReferenceFilterTimesPeriod / v.period_s;
    if (!(v.reference_filter_hz <= max_hz)) {
      t.fail("reference_filter_hz", "a finite number in (0, " + format_setting(max_hz) +
                                        "] Hz: at most 0.05/T for the reference filter's explicit update, a tenth "
                                        "of the " + format_setting(0.5 / v.period_s) + " Hz Nyquist frequency of the " +
                                        format_setting(v.period_s) + " s base tick");
    }
  }
  const bool filtered = v.reference_filter_hz > 0.0;
  for (const char* key : {"reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3", "direction_compensation_a"}) {
    if (!filtered && t.has(key)) {
      t.fail(key, "no such key while reference_filter_hz is absent (the reference's derivatives come from that "
                  "filter; set reference_filter_hz > 0 to feed them forward)");
    }
  }
  v.reference_velocity_a_per_m_s = t.number("reference_velocity_a_per_m_s", gain, v.reference_velocity_a_per_m_s);
  v.reference_acceleration_a_per_m_s2 =
      t.number("reference_acceleration_a_per_m_s2", gain, v.reference_acceleration_a_per_m_s2);
  v.reference_jerk_a_per_m_s3 = t.number("reference_jerk_a_per_m_s3", gain, v.reference_jerk_a_per_m_s3);
  v.direction_compensation_a =
      t.number("direction_compensation_a", SettingRange::closed(0.0, v.max_current_a), v.direction_compensation_a);
  v.direction_velocity_m_s = t.number("direction_velocity_m_s", SettingRange::positive(), v.direction_velocity_m_s);
  v.track_filtered_reference = t.boolean("track_filtered_reference", false);
  if (v.track_filtered_reference && !filtered) {
    t.fail("track_filtered_reference",
           "false while reference_filter_hz is absent (there is no filtered reference to track; set "
           "reference_filter_hz > 0)");
  }
}

// [axes.valve_law.model]: the identified valve (control/identified_valve.hpp; the model-predictor,
// damped and time-optimal steps of identified_valve_law, as `hsa-analyze valve-law` prints them),
// which the model predictor (valve_model_predictor.hpp) runs in the paper's predictor's place with
// the eigenvalues predictor_gamma. Every key is required: a half-given model would run on defaults
// nobody identified. I_max is the law's max_current_a. Returns false, changing nothing, without the
// table.
bool read_model(const LawSettings& law, ValveLawParams& v) {
  const auto t = law.table("model", false, "a table [" + law.key_path("model") + "] of the identified valve");
  if (!t) return false;
  t->reject_unknown_keys({"gain_m_per_a", "rest_position_m", "natural_frequency_hz", "damping_ratio",
                          "magnetic_lag_s", "dead_band_a", "delay_s", "predictor_gamma"});
  ValveModelPredictorParams m;
  m.enabled = true;
  IdentifiedValve& valve = m.valve;
  valve.gain_m_per_a = t->number("gain_m_per_a", SettingRange::positive());
  valve.rest_position_m = t->number("rest_position_m", SettingRange::any());
  valve.natural_frequency_hz = t->number("natural_frequency_hz", SettingRange::positive());
  valve.damping_ratio = t->number("damping_ratio", SettingRange::positive());
  valve.magnetic_lag_s = t->number("magnetic_lag_s", SettingRange::positive());
  valve.width_a = t->number("dead_band_a", SettingRange::closed(0.0, v.max_current_a));
  // The model's delay line holds whole base ticks, at most kMaxDelaySamples of them (the delay is
  // rounded to the nearest tick, as ValveModelPredictor and ValveTimeOptimal round it).
  valve.delay_s = t->number("delay_s", SettingRange::non_negative());
  if (std::lround(valve.delay_s / v.period_s) > ValveModelPredictor::kMaxDelaySamples) {
    t->fail("delay_s", "a finite number in [0, " +
                           format_setting((ValveModelPredictor::kMaxDelaySamples + 0.5) * v.period_s) +
                           ") s: at most " + std::to_string(ValveModelPredictor::kMaxDelaySamples) + " samples of the " +
                           format_setting(v.period_s) + " s base tick (the model's delay line)");
  }
  valve.current_max_a = v.max_current_a;
  const SettingRange gamma{.min = 0.0, .max = 1.0, .min_exclusive = true};
  if (!t->has("predictor_gamma")) {
    t->fail("predictor_gamma", "an array of 4 numbers in (0, 1] (the model predictor's eigenvalues; hsa-analyze "
                               "valve-law prints Table 2's halved)");
  }
  t->numbers("predictor_gamma", gamma, m.gamma.data(), m.gamma.size());
  // What the bounds above let through the predictor accepts; its constructor has the last word
  // here, off the RT thread.
  try {
    const ValveModelPredictor check(m, v.period_s);
  } catch (const std::invalid_argument& e) {
    law.fail("model", std::string("a model the valve loop's predictor accepts (") + e.what() + ")");
  }
  v.model_predictor = m;
  return true;
}

// [axes.valve_law.time_optimal]: full-effort moves on a jump of the reference
// (valve_time_optimal.hpp), run on the model of [axes.valve_law.model]; without that table there is
// no model to run them on, and the table is refused rather than left to look configured.
void read_time_optimal(const LawSettings& law, bool has_model, ValveLawParams& v) {
  const auto t = law.table("time_optimal", false,
                           "a table [" + law.key_path("time_optimal") + "] of the time-optimal moves");
  if (!t) return;
  if (!has_model) {
    law.fail("time_optimal", "no such table while [" + law.key_path("model") +
                                 "] is absent (the moves run on the identified model; add that table)");
  }
  t->reject_unknown_keys({"trigger_m", "margin_m", "horizon_samples"});
  ValveTimeOptimalParams o = time_optimal_on(v.model_predictor.valve);
  o.trigger_m = t->number("trigger_m", SettingRange::positive());
  o.margin_m = t->number("margin_m", SettingRange::non_negative());
  // Each sample runs at most two predictions of this length (a braking or rebuild run and a hold
  // run) within ValveTimeOptimal's budget of model steps per sample.
  constexpr int kMaxHorizon = ValveTimeOptimal::kPredictionBudget / 2;
  o.horizon_samples = whole_number(*t, "horizon_samples", 1, kMaxHorizon,
                                   "samples; two predictions of it fit the " +
                                       std::to_string(ValveTimeOptimal::kPredictionBudget) +
                                       " model steps a sample may run");
  try {
    const ValveTimeOptimal check(o, v.period_s, v.max_current_a);
  } catch (const std::invalid_argument& e) {
    law.fail("time_optimal", std::string("settings the time-optimal moves accept (") + e.what() + ")");
  }
  v.time_optimal = o;
}

// [axes.valve_law.predictive]: the predictive law (valve_predictive.hpp) and what its design
// (valve_predictive_design.hpp) builds it from, as `hsa-analyze valve-law --step predictive` prints
// it. The table holds the identified valve (identification::ValveModel, the fit's model, with the
// regulator's delay τ of eq 1 and the LVDT's noise; X_max is left out, the law's matrices do not use
// it) and the design's settings (ValvePredictiveSettings, and the law's own dither frequency). Every
// key is required, the settings too: a half-given model would run on defaults nobody identified,
// and the settings' defaults are one point of the design's grid chosen on the paper's valve, not on
// this one (the design chooses P, ρ, the dither's share and the disturbance's walk per valve).
// dither_frequency_hz alone is required only with a dither (dither_fraction·dead_band_a > 0) and
// refused without one. I_max is the law's max_current_a, T the base tick. The matrices are built
// here, off the RT thread (20 ms for the design's own sizes, valve_law_bounds has the most), and
// the law is constructed on them as the check; whatever either refuses (a delay τ + δ the delay
// line does not hold, a Riccati recursion that does not settle) is refused naming the table.
// Returns nullopt, changing nothing, without the table.
std::optional<ValvePredictiveSource> read_predictive(const LawSettings& law, ValveLawParams& v) {
  const auto t = law.table("predictive", false,
                           "a table [" + law.key_path("predictive") + "] of the identified valve and the predictive "
                                                                       "law's settings");
  if (!t) return std::nullopt;
  t->reject_unknown_keys({"gain_m_per_a", "rest_position_m", "natural_frequency_hz", "damping_ratio", "magnetic_lag_s",
                          "dead_band_a", "friction_band_m", "delay_s", "sensor_bandwidth_hz", "regulator_delay_s",
                          "lvdt_noise_m", "preview_samples", "horizon_extra_samples", "rate_weight_m2_per_a2",
                          "dither_fraction", "dither_frequency_hz", "headroom_fraction", "disturbance_walk_a",
                          "held_disturbance_walk_a", "velocity_walk_m_s", "direction_velocity_m_s", "max_qp_iterations"});
  ValvePredictiveSource source;
  ValvePredictiveValve& valve = source.valve;
  identification::ValveModel& m = valve.model;
  m.gain_m_per_a = t->number("gain_m_per_a", SettingRange::positive());
  m.rest_position_m = t->number("rest_position_m", SettingRange::any());
  m.natural_frequency_hz = t->number("natural_frequency_hz", SettingRange::positive());
  m.damping_ratio = t->number("damping_ratio", SettingRange::positive());
  m.magnetic_lag_s = t->number("magnetic_lag_s", SettingRange::positive());
  m.width_a = t->number("dead_band_a", SettingRange::closed(0.0, v.max_current_a));
  m.friction_band_m = t->number("friction_band_m", SettingRange::non_negative());
  m.delay_s = t->number("delay_s", SettingRange::non_negative());
  m.sensor_bandwidth_hz = t->number("sensor_bandwidth_hz", SettingRange::positive());
  // Eq 1's τ counts from the start of the period the command is held over: at least that period.
  valve.regulator_delay_s = t->number("regulator_delay_s", SettingRange::positive());
  if (!(valve.regulator_delay_s >= v.period_s)) {
    t->fail("regulator_delay_s", "a finite number >= " + format_setting(v.period_s) +
                                     " s, the base tick (eq 1's delay counts the period the command is held over)");
  }
  valve.lvdt_noise_m = t->number("lvdt_noise_m", SettingRange::positive());
  valve.current_max_a = v.max_current_a;

  ValvePredictiveSettings& s = source.settings;
  s.preview_samples = whole_number(*t, "preview_samples", 1, valve_law_bounds::kMaxPreviewSamples,
                                   "samples of the reference read ahead of the reading's target");
  s.horizon_extra_samples = whole_number(*t, "horizon_extra_samples", 1, valve_law_bounds::kMaxHorizonExtraSamples,
                                         "samples the QP's horizon runs past the preview");
  s.rate_weight_m2_per_a2 =
      t->number("rate_weight_m2_per_a2", SettingRange::positive(valve_law_bounds::kMaxRateWeightM2PerA2));
  // The commands' box is [h·a, I_max − h·a] for the dither's amplitude a = fraction·w and the share
  // h of it kept off the limits: it must leave current between its ends.
  s.headroom_fraction = t->number("headroom_fraction", SettingRange::closed(0.0, 1.0));
  s.dither_fraction = t->number("dither_fraction", SettingRange::non_negative());
  const double kept_off = s.headroom_fraction * m.width_a;  // a limit's headroom per unit of dither_fraction
  if (!(2.0 * s.dither_fraction * kept_off < v.max_current_a)) {
    t->fail("dither_fraction", "a finite number in [0, " + format_setting(0.5 * v.max_current_a / kept_off) +
                                   "): the box keeps headroom_fraction·dither_fraction·dead_band_a off both 0 and "
                                   "max_current_a = " + format_setting(v.max_current_a) +
                                   " A, and must leave current between them");
  }
  const bool dithered = s.dither_fraction * m.width_a > 0.0;
  double dither_hz = 0.0;
  if (dithered) {
    dither_hz = dither_frequency(*t, "dither_frequency_hz", v.period_s);
  } else if (t->has("dither_frequency_hz")) {
    t->fail("dither_frequency_hz", "no frequency while dither_fraction·dead_band_a is 0 (the dither is off)");
  }
  s.disturbance_walk_a = t->number("disturbance_walk_a", SettingRange::positive());
  s.held_disturbance_walk_a = t->number("held_disturbance_walk_a", SettingRange::positive());
  s.velocity_walk_m_s = t->number("velocity_walk_m_s", SettingRange::positive());
  s.direction_velocity_m_s = t->number("direction_velocity_m_s", SettingRange::positive());
  s.max_qp_iterations = whole_number(*t, "max_qp_iterations", 1, valve_law_bounds::kMaxQpIterations,
                                     "the QP's iterations a tick, after which its commands are clamped to the box");
  ValvePredictiveParams p;
  try {
    p = valve_predictive_params(valve, v.period_s, dither_hz, s);
    const ValvePredictiveLaw check(p);
  } catch (const std::invalid_argument& e) {
    law.fail("predictive", std::string("settings the predictive law accepts (") + e.what() + ")");
  }
  // Every sample starts with the product of the H × n map from the state to the unconstrained
  // commands, before the QP's first step; past the law's budget a sample, a ramp included, would
  // overrun it at every tick. n = 6 + D + 2·(P + 1) counts the delay D the design derived.
  const long product = static_cast<long>(p.qp_linear.size());
  if (product > ValvePredictiveLaw::kQpWorkBudget) {
    law.fail("predictive", "settings whose QP fits its work budget: the product of its H x n = " +
                               std::to_string(p.horizon_samples) + " x " +
                               std::to_string(product / p.horizon_samples) + " map, " + std::to_string(product) +
                               " multiply-adds each sample, is more than the " +
                               std::to_string(ValvePredictiveLaw::kQpWorkBudget) +
                               " a sample may take (fewer preview_samples or horizon_extra_samples)");
  }
  v.predictive = std::move(p);
  return source;
}

// With [axes.valve_law.predictive] eq 31's law does not run: its gains, dither, feed-forward and
// predictor, and the model and time-optimal tables that serve it, would only look configured, and
// are refused. What stays is what the predictive law and the safety chain use: max_current_a
// (I_max), bias_current_a (the null command) and spool_at_full_opening_m (the PI's opening).
void refuse_eq31_beside_predictive(const LawSettings& t) {
  const std::string table = "[" + t.key_path("predictive") + "]";
  for (const char* key : {"feedforward_a_per_m", "integral_a_per_m_s", "proportional_a_per_m",
                          "dead_band_compensation_a", "dead_band_error_m", "velocity_a_per_m_s",
                          "acceleration_a_per_m_s2", "dither_amplitude_a", "dither_frequency_hz",
                          "reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3", "reference_filter_hz", "track_filtered_reference",
                          "direction_compensation_a", "direction_velocity_m_s", "predictor_gamma"}) {
    if (t.has(key)) {
      t.fail(key, "no such key while " + table +
                      " is present (the predictive law decides the current in eq 31's place: eq 31's gains, dither, "
                      "feed-forward and predictor do not run; the predictive law's own settings are in that table)");
    }
  }
  if (t.has("model")) {
    t.fail("model", "no such table while " + table +
                        " is present (the predictive law runs on the identified valve in its own table, and the "
                        "model predictor does not run)");
  }
  if (t.has("time_optimal")) {
    t.fail("time_optimal", "no such table while " + table +
                               " is present (the time-optimal moves are eq 31's, which does not run)");
  }
}

// The valve loop's parameters of [axes.valve_law], with control/'s names: ValveLawParams, the
// opening-to-spool map and the state predictor's eigenvalues (the paper's predictor's, or with the
// model table the model predictor's); or, with the predictive table, the predictive law in eq 31's
// place, whose design inputs are returned for describe().
std::optional<ValvePredictiveSource> read_valve_law(const LawSettings& axis, CascadeParams& c) {
  const auto t = axis.table("valve_law", true,
                            "a table [" + axis.key_path("valve_law") +
                                "] (drive = \"proportional\" needs the valve loop's parameters)");
  t->reject_unknown_keys({"bias_current_a", "max_current_a", "feedforward_a_per_m", "integral_a_per_m_s",
                          "proportional_a_per_m", "dead_band_compensation_a", "dead_band_error_m",
                          "velocity_a_per_m_s", "acceleration_a_per_m_s2", "dither_amplitude_a",
                          "dither_frequency_hz", "reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3", "reference_filter_hz", "track_filtered_reference",
                          "direction_compensation_a", "direction_velocity_m_s", "spool_at_full_opening_m",
                          "predictor_gamma", "model", "time_optimal", "predictive"});
  ValveLawParams& v = c.valve;
  const SettingRange gain = SettingRange::closed(0.0, valve_law_bounds::kMaxGain);
  v.max_current_a = t->number("max_current_a", SettingRange::positive(valve_law_bounds::kMaxCurrentA), v.max_current_a);
  v.bias_current_a = t->number("bias_current_a", SettingRange::closed(0.0, v.max_current_a));
  if (t->has("predictive")) refuse_eq31_beside_predictive(*t);
  v.feedforward_a_per_m = t->number("feedforward_a_per_m", gain, v.feedforward_a_per_m);
  v.integral_a_per_m_s = t->number("integral_a_per_m_s", gain, v.integral_a_per_m_s);
  v.proportional_a_per_m = t->number("proportional_a_per_m", gain, v.proportional_a_per_m);
  v.dead_band_compensation_a = t->number("dead_band_compensation_a", gain, v.dead_band_compensation_a);
  v.dead_band_error_m = t->number("dead_band_error_m", SettingRange::positive(), v.dead_band_error_m);
  v.velocity_a_per_m_s = t->number("velocity_a_per_m_s", gain, v.velocity_a_per_m_s);
  v.acceleration_a_per_m_s2 = t->number("acceleration_a_per_m_s2", gain, v.acceleration_a_per_m_s2);
  v.dither_amplitude_a =
      t->number("dither_amplitude_a", SettingRange::closed(0.0, 0.5 * v.max_current_a), v.dither_amplitude_a);
  if (v.dither_amplitude_a > 0.0) {
    v.dither_frequency_hz = dither_frequency(*t, "dither_frequency_hz", v.period_s);
  } else if (t->has("dither_frequency_hz")) {
    t->fail("dither_frequency_hz", "no frequency while dither_amplitude_a is 0 (the dither is off)");
  }
  read_model_inverse(*t, v);
  c.spool_at_full_opening_m = t->number("spool_at_full_opening_m", SettingRange::positive(), c.spool_at_full_opening_m);
  const bool has_model = read_model(*t, v);
  read_time_optimal(*t, has_model, v);
  if (has_model && t->has("predictor_gamma")) {
    t->fail("predictor_gamma", "no such key while [" + t->key_path("model") +
                                   "] is present (the model predictor runs in the paper's predictor's place; its "
                                   "eigenvalues are model.predictor_gamma)");
  }
  std::array<double, 4> gamma = kTable2Gamma;
  t->numbers("predictor_gamma", {.min = 0.0, .max = 1.0, .min_exclusive = true}, gamma.data(), gamma.size());
  c.predictor = predictor_gains(gamma);
  return read_predictive(*t, v);
}

}  // namespace

ProportionalCascadeLaw::ProportionalCascadeLaw(const CascadeParams& params, const GainBounds& bounds,
                                               std::shared_ptr<const GainGate> gate,
                                               std::optional<ValvePredictiveSource> predictive)
    : PiCascadeLaw(params, bounds, std::move(gate)), predictive_(std::move(predictive)) {
  if (params.drive != ValveDrive::proportional) {
    throw std::invalid_argument("the proportional cascade needs a proportional valve drive");
  }
  if (predictive_ && !params.valve.predictive.enabled) {
    throw std::invalid_argument("the predictive law's design inputs were given without its law (valve.predictive "
                                "is not enabled)");
  }
}

std::unique_ptr<ControlLaw> ProportionalCascadeLaw::from_settings(const LawSettings& axis, const LawTiming& timing) {
  // The valve loop runs every base tick, the PI every ticks_per_cylinder_tick: the periods are
  // built the way control::Cascade checks them.
  CascadeParams c;
  c.drive = ValveDrive::proportional;
  c.valve.period_s = timing.base_period_s;
  c.valve_ticks_per_cylinder_tick = timing.ticks_per_cylinder_tick;
  GainBounds bounds;
  std::shared_ptr<const GainGate> gate;
  c.cylinder = read_pi(axis, timing, bounds, gate);
  std::optional<ValvePredictiveSource> predictive = read_valve_law(axis, c);
  return std::make_unique<ProportionalCascadeLaw>(c, bounds, std::move(gate), std::move(predictive));
}

std::unique_ptr<ControlLaw> ProportionalCascadeLaw::clone() const {
  return std::make_unique<ProportionalCascadeLaw>(cascade_.params(), gain_bounds(), gate(), predictive_);
}

double ProportionalCascadeLaw::null_command() const noexcept { return cascade_.params().valve.bias_current_a; }

// A spring-centred proportional valve is closed at its null current and also de-energized, where
// the spring parks the spool in its fail-safe zone.
std::string ProportionalCascadeLaw::safe_command_refusal(double command, double band) const {
  const ValveLawParams& v = cascade_.params().valve;
  if (!(command >= 0.0 && command <= v.max_current_a)) {
    return "a finite number in [0, " + format_setting(v.max_current_a) + "]";
  }
  if (command == 0.0 || std::abs(command - v.bias_current_a) <= band * v.max_current_a) return "";
  return "a current that closes the valve: 0 A (de-energized) or within " + format_setting(band * v.max_current_a) +
         " A of the null current valve_law.bias_current_a = " + format_setting(v.bias_current_a) +
         " A (safe_command_band " + format_setting(band) + " of max_current_a)";
}

namespace {

std::string describe_model_inverse(const ValveLawParams& v) {
  if (!(v.reference_filter_hz > 0.0)) return "    feed-forward  off (no reference_filter_hz): eq 31's K_r·r only\n";
  return "    feed-forward  reference filter " + format_setting(v.reference_filter_hz) + " Hz, K_rv " +
         format_setting(v.reference_velocity_a_per_m_s) + ", K_ra " + format_setting(v.reference_acceleration_a_per_m_s2) +
         ", K_rj " + format_setting(v.reference_jerk_a_per_m_s3) + ",\n                  tracks " +
         (v.track_filtered_reference ? "the filtered reference" : "the reference") + ", direction dI_d " +
         format_setting(v.direction_compensation_a) + " A over " + format_setting(v.direction_velocity_m_s) + " m/s\n";
}

std::string describe_predictor(const ValveLawParams& v) {
  const ValveModelPredictorParams& m = v.model_predictor;
  if (!m.enabled) return "    predictor     the paper's (Canuto et al. (2014) eqs 15-16)\n";
  const IdentifiedValve& i = m.valve;
  std::string gamma;
  for (std::size_t k = 0; k < m.gamma.size(); ++k) gamma += (k ? ", " : "") + format_setting(m.gamma[k]);
  return "    predictor     the identified model's: g " + format_setting(i.gain_m_per_a) + " m/A, X_min " +
         format_setting(i.rest_position_m) + " m, f0 " + format_setting(i.natural_frequency_hz) + " Hz, zeta " +
         format_setting(i.damping_ratio) + ",\n                  tau_a " + format_setting(i.magnetic_lag_s) + " s, w " +
         format_setting(i.width_a) + " A, delay " + format_setting(i.delay_s) + " s, gamma " + gamma + "\n";
}

std::string describe_time_optimal(const ValveLawParams& v) {
  const ValveTimeOptimalParams& o = v.time_optimal;
  if (!o.enabled) return "    time-optimal  off\n";
  return "    time-optimal  on: trigger " + format_setting(o.trigger_m) + " m, margin " + format_setting(o.margin_m) +
         " m, horizon " + std::to_string(o.horizon_samples) + " samples\n";
}

// The law's sizes, box and dither from its matrices; ρ, the walks and the identified valve from what
// they were built on, when the law came from the configuration.
std::string describe_predictive(const ValvePredictiveParams& p, const std::optional<ValvePredictiveSource>& source) {
  const double dither_hz = p.dither_half_period_samples > 0 ? 0.5 / (p.dither_half_period_samples * p.period_s) : 0.0;
  std::string text = "    predictive    on: P " + std::to_string(p.preview_samples) + " samples of preview (" +
                     format_setting(p.preview_samples * p.period_s) + " s), H " + std::to_string(p.horizon_samples) +
                     " samples, D " + std::to_string(p.delay_samples) + " samples of delay, commands in [" +
                     format_setting(p.lower_a) + ", " + format_setting(p.upper_a) + "] A,\n                  dither " +
                     format_setting(p.dither_amplitude_a) + " A at " + format_setting(dither_hz) + " Hz, v_d " +
                     format_setting(p.direction_velocity_m_s) + " m/s, at most " + std::to_string(p.max_qp_iterations) +
                     " QP iterations a tick\n";
  if (!source) return text + "                  (built in code: the settings and the valve it was designed on not kept)\n";
  const ValvePredictiveSettings& s = source->settings;
  const identification::ValveModel& m = source->valve.model;
  return text + "                  designed with rho " + format_setting(s.rate_weight_m2_per_a2) + " m^2/A^2, dither " +
         format_setting(s.dither_fraction) + " w (" + format_setting(s.headroom_fraction) +
         " of it kept off the limits), walks " + format_setting(s.disturbance_walk_a) + " A (held target " +
         format_setting(s.held_disturbance_walk_a) + " A) and " +
         format_setting(s.velocity_walk_m_s) + " m/s a sample,\n                  on g " + format_setting(m.gain_m_per_a) +
         " m/A, X_min " + format_setting(m.rest_position_m) + " m, f0 " + format_setting(m.natural_frequency_hz) +
         " Hz, zeta " + format_setting(m.damping_ratio) + ", tau_a " + format_setting(m.magnetic_lag_s) + " s, w " +
         format_setting(m.width_a) + " A,\n                  s_f " + format_setting(m.friction_band_m) + " m, delay " +
         format_setting(m.delay_s) + " s + regulator " + format_setting(source->valve.regulator_delay_s) + " s, LVDT " +
         format_setting(m.sensor_bandwidth_hz) + " Hz and " + format_setting(source->valve.lvdt_noise_m) + " m rms\n";
}

}  // namespace

std::string ProportionalCascadeLaw::describe() const {
  const ValveLawParams& v = cascade_.params().valve;
  const std::string opening = "full opening " + format_setting(cascade_.params().spool_at_full_opening_m) + " m";
  if (v.predictive.enabled) {
    // Eq 31's gains, feed-forward, predictor and moves are left at their defaults and do not run:
    // their lines would describe a law that is not there.
    return describe_pi() + "    valve law     the predictive law in eq 31's place (eq 31, its feed-forward, predictor "
                           "and moves do not run):\n                  bias " +
           format_setting(v.bias_current_a) + " A (the null command), max " + format_setting(v.max_current_a) + " A, " +
           opening + "\n" + describe_predictive(v.predictive, predictive_);
  }
  return describe_pi() + "    valve law     bias " + format_setting(v.bias_current_a) + " A, max " + format_setting(v.max_current_a) +
         " A, K_r " + format_setting(v.feedforward_a_per_m) + ", K_i " + format_setting(v.integral_a_per_m_s) + ", k_p " +
         format_setting(v.proportional_a_per_m) + ", dI " + format_setting(v.dead_band_compensation_a) + " A,\n                  K_v " +
         format_setting(v.velocity_a_per_m_s) + ", K_a " + format_setting(v.acceleration_a_per_m_s2) + ", dither " +
         format_setting(v.dither_amplitude_a) + " A at " + format_setting(v.dither_frequency_hz) + " Hz, " + opening +
         "\n" + describe_model_inverse(v) + describe_predictor(v) + describe_time_optimal(v) + "    predictive    off\n";
}
bool ProportionalCascadeLaw::saturated() const noexcept { return cascade_.valve_saturated(); }

}  // namespace hsa::control
