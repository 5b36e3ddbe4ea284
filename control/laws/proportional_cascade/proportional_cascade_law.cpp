#include "control/laws/proportional_cascade/proportional_cascade_law.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <stdexcept>
#include <utility>

namespace hsa::control {

namespace {

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
  const std::string whole = "a whole number in [1, " + std::to_string(kMaxHorizon) +
                            "] (samples; two predictions of it fit the " +
                            std::to_string(ValveTimeOptimal::kPredictionBudget) + " model steps a sample may run)";
  const double horizon = t->number("horizon_samples", SettingRange::closed(1.0, kMaxHorizon));
  if (horizon != std::floor(horizon)) t->fail("horizon_samples", whole);
  o.horizon_samples = static_cast<int>(horizon);
  try {
    const ValveTimeOptimal check(o, v.period_s, v.max_current_a);
  } catch (const std::invalid_argument& e) {
    law.fail("time_optimal", std::string("settings the time-optimal moves accept (") + e.what() + ")");
  }
  v.time_optimal = o;
}

// The valve loop's parameters of [axes.valve_law], with control/'s names: ValveLawParams, the
// opening-to-spool map and the state predictor's eigenvalues (the paper's predictor's, or with the
// model table the model predictor's).
void read_valve_law(const LawSettings& axis, CascadeParams& c) {
  const auto t = axis.table("valve_law", true,
                            "a table [" + axis.key_path("valve_law") +
                                "] (drive = \"proportional\" needs the valve loop's parameters)");
  t->reject_unknown_keys({"bias_current_a", "max_current_a", "feedforward_a_per_m", "integral_a_per_m_s",
                          "proportional_a_per_m", "dead_band_compensation_a", "dead_band_error_m",
                          "velocity_a_per_m_s", "acceleration_a_per_m_s2", "dither_amplitude_a",
                          "dither_frequency_hz", "reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2",
                          "reference_jerk_a_per_m_s3", "reference_filter_hz", "track_filtered_reference",
                          "direction_compensation_a", "direction_velocity_m_s", "spool_at_full_opening_m",
                          "predictor_gamma", "model", "time_optimal"});
  ValveLawParams& v = c.valve;
  const SettingRange gain = SettingRange::closed(0.0, valve_law_bounds::kMaxGain);
  v.max_current_a = t->number("max_current_a", SettingRange::positive(valve_law_bounds::kMaxCurrentA), v.max_current_a);
  v.bias_current_a = t->number("bias_current_a", SettingRange::closed(0.0, v.max_current_a));
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
    // A square wave of whole base ticks: the half period must be n·T.
    v.dither_frequency_hz = t->number("dither_frequency_hz", SettingRange::positive());
    const double half_period_ticks = 0.5 / (v.dither_frequency_hz * v.period_s);
    if (!(half_period_ticks >= 1.0 && std::abs(half_period_ticks - std::round(half_period_ticks)) < 1e-6)) {
      char expected[160];
      std::snprintf(expected, sizeof expected,
                    "a frequency whose half period is a whole number of %g s base ticks (%g Hz, %g Hz, %g Hz, ...)",
                    v.period_s, 0.5 / v.period_s, 0.25 / v.period_s, 0.5 / (3 * v.period_s));
      t->fail("dither_frequency_hz", expected);
    }
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
}

}  // namespace

ProportionalCascadeLaw::ProportionalCascadeLaw(const CascadeParams& params, const GainBounds& bounds,
                                               std::shared_ptr<const GainGate> gate)
    : PiCascadeLaw(params, bounds, std::move(gate)) {
  if (params.drive != ValveDrive::proportional) {
    throw std::invalid_argument("the proportional cascade needs a proportional valve drive");
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
  read_valve_law(axis, c);
  return std::make_unique<ProportionalCascadeLaw>(c, bounds, std::move(gate));
}

std::unique_ptr<ControlLaw> ProportionalCascadeLaw::clone() const {
  return std::make_unique<ProportionalCascadeLaw>(cascade_.params(), gain_bounds(), gate());
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

}  // namespace

std::string ProportionalCascadeLaw::describe() const {
  const ValveLawParams& v = cascade_.params().valve;
  return describe_pi() + "    valve law     bias " + format_setting(v.bias_current_a) + " A, max " + format_setting(v.max_current_a) +
         " A, K_r " + format_setting(v.feedforward_a_per_m) + ", K_i " + format_setting(v.integral_a_per_m_s) + ", k_p " +
         format_setting(v.proportional_a_per_m) + ", dI " + format_setting(v.dead_band_compensation_a) + " A,\n                  K_v " +
         format_setting(v.velocity_a_per_m_s) + ", K_a " + format_setting(v.acceleration_a_per_m_s2) + ", dither " +
         format_setting(v.dither_amplitude_a) + " A at " + format_setting(v.dither_frequency_hz) + " Hz, full opening " +
         format_setting(cascade_.params().spool_at_full_opening_m) + " m\n" + describe_model_inverse(v) +
         describe_predictor(v) + describe_time_optimal(v);
}
bool ProportionalCascadeLaw::saturated() const noexcept { return cascade_.valve_saturated(); }

}  // namespace hsa::control
