#include "control/laws/pi_cascade_law.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace hsa::control {

// The RT path of every PI cascade law (control_law.hpp: activate, tick, open_loop_tick, set_gains
// run on the RT thread) calls only what cannot throw.
static_assert(noexcept(std::declval<Cascade&>().activate(0.0, 0.0, 0.0)));
static_assert(noexcept(std::declval<Cascade&>().tick(LawInputs{}, 0)));
static_assert(noexcept(std::declval<Cascade&>().open_loop_tick(0.0, 0.0, 0)));
static_assert(noexcept(std::declval<Cascade&>().set_cylinder_gains(0.0, 0.0)));
static_assert(noexcept(std::declval<const Cascade&>().cylinder().limited_setpoint()));
static_assert(noexcept(std::declval<const Cascade&>().cylinder().saturated()));

PiCascadeLaw::PiCascadeLaw(const CascadeParams& params, const GainBounds& bounds,
                           std::shared_ptr<const GainGate> gate)
    : cascade_(params), bounds_(bounds), gate_(std::move(gate)) {
  const PiParams& pi = params.cylinder;
  if (!std::isfinite(bounds.max_kp) || !(pi.kp > 0.0) || !(pi.kp <= bounds.max_kp) ||
      !std::isfinite(bounds.max_ki) || !(pi.ki >= 0.0) || !(pi.ki <= bounds.max_ki)) {
    throw std::invalid_argument("the PI gains kp " + format_setting(pi.kp) + ", ki " + format_setting(pi.ki) +
                                " must lie within finite bounds (0, max_kp " + format_setting(bounds.max_kp) +
                                "] and [0, max_ki " + format_setting(bounds.max_ki) + "]");
  }
}

double PiCascadeLaw::max_speed_m_s() const noexcept {
  return cascade_.params().cylinder.max_setpoint_rate_m_s;
}

void PiCascadeLaw::activate(double rod_position_m, double spool_position_m, double current_opening) noexcept {
  cascade_.activate(rod_position_m, spool_position_m, current_opening);
}

LawOutput PiCascadeLaw::tick(const LawInputs& in, std::uint64_t base_tick) noexcept {
  return cascade_.tick(in, base_tick);
}

LawOutput PiCascadeLaw::open_loop_tick(double opening, double spool_position_m, std::uint64_t base_tick) noexcept {
  return cascade_.open_loop_tick(opening, spool_position_m, base_tick);
}

double PiCascadeLaw::limited_setpoint_m() const noexcept { return cascade_.cylinder().limited_setpoint(); }

bool PiCascadeLaw::saturated() const noexcept { return cascade_.cylinder().saturated(); }

RuntimeGains PiCascadeLaw::gains() const noexcept {
  return {cascade_.params().cylinder.kp, cascade_.params().cylinder.ki};
}

void PiCascadeLaw::check_gains(const RuntimeGains& g) const {
  if (!std::isfinite(g.kp) || !std::isfinite(g.ki)) throw std::invalid_argument("the gains must be finite numbers");
  if (!(g.kp > 0.0) || g.kp > bounds_.max_kp) {
    throw std::invalid_argument("kp " + format_setting(g.kp) + " is outside (0, max_kp " + format_setting(bounds_.max_kp) + "] 1/m");
  }
  if (!(g.ki >= 0.0) || g.ki > bounds_.max_ki) {
    throw std::invalid_argument("ki " + format_setting(g.ki) + " is outside [0, max_ki " + format_setting(bounds_.max_ki) +
                                "] 1/(m s)");
  }
  if (gate_) {
    const GateVerdict verdict = gate_->judge({g.kp, g.ki});
    if (!verdict.passed()) throw std::invalid_argument(verdict.refusal);
  }
}

void PiCascadeLaw::set_gains(const RuntimeGains& g) noexcept {
  // Checked by check_gains() on the caller's thread: finite and within the bounds, which is all
  // PiController::set_gains refuses, so it takes them.
  (void)cascade_.set_cylinder_gains(g.kp, g.ki);
}

namespace {

std::string describe_feedforward(const PiParams& pi) {
  const auto gains = [](const FeedforwardGains& g) {
    return format_setting(g.velocity) + " s/m, " + format_setting(g.accel) + " s²/m, " + format_setting(g.jerk) + " s³/m";
  };
  if (pi.feedforward_schedule.empty())
    return gains({pi.velocity_feedforward, pi.acceleration_feedforward, pi.jerk_feedforward});
  // Four digits: the gains are a model's inverse, not settings to be copied back.
  std::string text = "following the plant set's working points (s/m, s²/m, s³/m):";
  const FeedforwardSchedule& s = pi.feedforward_schedule;
  for (std::size_t i = 0; i < s.count; ++i) {
    char line[128];
    std::snprintf(line, sizeof line, "\n                  at %5.1f mm: %.4g, %.4g, %.4g", s.points[i].position_m * 1e3,
                  s.points[i].gains.velocity, s.points[i].gains.accel, s.points[i].gains.jerk);
    text += line;
  }
  return text;
}

}  // namespace

std::string PiCascadeLaw::describe_pi() const {
  const PiParams& pi = cascade_.params().cylinder;
  return "    PI            kp " + format_setting(pi.kp) + " 1/m, ki " + format_setting(pi.ki) + " 1/(m s) (at run time up to " +
         format_setting(bounds_.max_kp) + " and " + format_setting(bounds_.max_ki) + "), max speed " +
         format_setting(pi.max_setpoint_rate_m_s) + " m/s, dead band " + format_setting(pi.dead_band_m) +
         " m, integral dead band " + format_setting(pi.integral_dead_band_m) + " m, output limit " + format_setting(pi.output_limit) +
         ", feed-forward " + describe_feedforward(pi) + "\n" +
         (gate_ ? gate_->describe({pi.kp, pi.ki}) : std::string());
}

// max_speed_m_s is required: it limits how fast the rod may be asked to move, and an axis without
// that limit would step its setpoint at whatever a client sends.
PiParams PiCascadeLaw::read_pi(const LawSettings& axis, const LawTiming& timing, GainBounds& bounds,
                               std::shared_ptr<const GainGate>& gate) {
  const auto t = axis.table("pi", true, "a table of PI gains [" + axis.key_path("pi") + "]");
  t->reject_unknown_keys({"kp", "ki", "max_kp", "max_ki", "max_speed_m_s", "dead_band_m",
                          "integral_dead_band_m", "output_limit", "velocity_feedforward",
                          "min_gain_margin_db", "min_phase_margin_deg", "plants", "acceleration_feedforward",
                          "jerk_feedforward", "feedforward"});
  PiParams p;
  p.period_s = timing.base_period_s * timing.ticks_per_cylinder_tick;
  p.kp = t->number("kp", SettingRange::positive(pi_bounds::kMaxKp));
  p.ki = t->number("ki", SettingRange::closed(0.0, pi_bounds::kMaxKi));
  bounds.max_kp = t->number("max_kp", SettingRange::closed(p.kp, pi_bounds::kMaxKp),
                            std::min(kDefaultGainBoundFactor * p.kp, pi_bounds::kMaxKp));
  bounds.max_ki = t->number("max_ki", SettingRange::closed(p.ki, pi_bounds::kMaxKi),
                            std::min(kDefaultGainBoundFactor * p.ki, pi_bounds::kMaxKi));
  p.max_setpoint_rate_m_s = t->number("max_speed_m_s", SettingRange::positive(pi_bounds::kMaxSpeedMPerS));
  const SettingRange band = SettingRange::closed(0.0, pi_bounds::kMaxDeadBandM);
  p.dead_band_m = t->number("dead_band_m", band, p.dead_band_m);
  p.integral_dead_band_m = t->number("integral_dead_band_m", band, p.integral_dead_band_m);
  p.output_limit = t->number("output_limit", SettingRange::positive(1.0), p.output_limit);
  // Valve opening per m/s, m/s² and m/s³ of the setpoint's velocity (a move's, or a stream's
  // setpoint_t.velocity_ff_m_s), acceleration and jerk (a move's): the inverted plant
  // (motion_feedforward.hpp). They default to the inverse of the paper's nominal plant (Puglisi et
  // al. 2015 eq 52); 0 turns a term off.
  p.velocity_feedforward = t->number("velocity_feedforward",
                                     SettingRange::closed(0.0, pi_bounds::kMaxVelocityFeedforward),
                                     kNominalFeedforward.velocity);
  p.acceleration_feedforward = t->number("acceleration_feedforward",
                                         SettingRange::closed(0.0, pi_bounds::kMaxAccelFeedforward),
                                         kNominalFeedforward.accel);
  p.jerk_feedforward =
      t->number("jerk_feedforward", SettingRange::closed(0.0, pi_bounds::kMaxJerkFeedforward), kNominalFeedforward.jerk);

  // The gain gate (gain_gate.hpp): its minimums default to just below the paper's own design on
  // Table A3. A gain margin above 40 dB or a phase margin of 90° or more would refuse every PI.
  MarginRequirements min;
  min.min_gain_margin_db = t->number("min_gain_margin_db", SettingRange::closed(0.0, pi_bounds::kMaxMinGainMarginDb),
                                     min.min_gain_margin_db);
  min.min_phase_margin_deg = t->number(
      "min_phase_margin_deg", {.min = 0.0, .max = pi_bounds::kMaxMinPhaseMarginDeg, .max_exclusive = true},
      min.min_phase_margin_deg);
  // The plants the gate judges on: a plant-set file of this rig's (`plants`, from `hsa-analyze
  // identify --set`), or the paper's Table A3.
  std::optional<GatePlantSet> identified = t->plant_set("plants");
  const bool own_set = identified.has_value();
  GatePlantSet plants = own_set ? std::move(*identified) : table_a3_plant_set();

  // feedforward = "plants": the feed-forward follows the working point, inverting the gate's plant
  // at the setpoint's position (feedforward_schedule.hpp) instead of three fixed gains. The plants
  // are the gate's: the axis's plant set, or Table A3 (the paper's rig) without one.
  constexpr std::string_view kFeedforwardChoice =
      "\"gains\" (the three *_feedforward gains) or \"plants\" (the plant set's plants, inverted at the setpoint's position)";
  const std::string feedforward = t->text("feedforward", kFeedforwardChoice).value_or("gains");
  if (feedforward == "plants") {
    for (const std::string_view key : {"velocity_feedforward", "acceleration_feedforward", "jerk_feedforward"}) {
      if (t->has(key)) t->fail(key, "no fixed feed-forward gain with feedforward = \"plants\" (the schedule replaces it)");
    }
    try {
      p.feedforward_schedule = make_feedforward_schedule(plants.plants);
    } catch (const std::invalid_argument& e) {
      t->fail(own_set ? "plants" : "feedforward", std::string("plants that can be inverted (") + e.what() + ")");
    }
  } else if (feedforward != "gains") {
    t->fail("feedforward", std::string(kFeedforwardChoice));
  }
  auto checked = std::make_shared<const GainGate>(GainGate{std::move(plants), min});
  if (const GateVerdict verdict = checked->judge({p.kp, p.ki}); !verdict.passed()) {
    t->fail("kp", "gains that pass the gain gate (with ki " + format_setting(p.ki) +
                      " they are refused: " + verdict.refusal + ")");
  }
  gate = std::move(checked);
  return p;
}

}  // namespace hsa::control
