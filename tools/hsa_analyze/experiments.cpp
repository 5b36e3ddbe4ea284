#include "tools/hsa_analyze/experiments.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/rig.hpp"

namespace hsa::analyze {

namespace {

constexpr double kSineCentreM = 0.150;
constexpr double kSineAmplitudeM = 0.125;
constexpr double kTailS = 0.5;  // window of the oscillation check

// The rig in servo-valve mode under the PI, advanced one PI sample at a time. The sample reads the
// encoder, computes the opening and writes it, then the rig runs for one PI period (10 steps of
// 100 µs): the same order the daemon uses, with the output acting within the sample it was computed.
class Lockstep {
 public:
  Lockstep(double position_m, double load_kg, const control::PiParams& pi_params)
      : rig_(config(position_m, load_kg)), pi_(pi_params) {
    steps_per_sample_ = static_cast<int>(std::lround(pi_params.period_s / rig_.config().step_s));
    pi_.activate(position());
  }

  [[nodiscard]] double position() const { return rig_.read().encoder_m.value; }
  [[nodiscard]] double time_s() const { return rig_.time_s(); }
  [[nodiscard]] double period_s() const { return pi_.params().period_s; }
  void set_load(double kg) { rig_.set_load_mass(kg); }

  // One PI sample with this setpoint; returns the error the PI saw (setpoint − measured position).
  double sample(double setpoint_m) {
    const double error = setpoint_m - position();
    rig_.set_valve_command(pi_.update(setpoint_m, position()));
    for (int i = 0; i < steps_per_sample_; ++i) rig_.step();
    return error;
  }

 private:
  static sim::RigConfig config(double position_m, double load_kg) {
    sim::RigConfig c;
    c.valve = sim::ValveKind::servo;
    c.initial_position_m = position_m;
    c.load_kg = load_kg;
    return c;
  }

  sim::Rig rig_;
  control::PiController pi_;
  int steps_per_sample_ = 10;
};

// Number of PI samples covering duration_s.
long samples(double duration_s, double period_s) { return std::lround(duration_s / period_s); }

double sine_setpoint(double omega_rad_s, double t_s) {
  return kSineCentreM + kSineAmplitudeM * std::sin(omega_rad_s * t_s);
}

}  // namespace

StepMetrics run_step(double position_m, double load_kg, double step_m, double run_s, const control::PiParams& pi) {
  Lockstep loop(position_m, load_kg, pi);
  // Settle first: the rod starts at rest, but the load has to be taken up by the chamber pressures
  // and the integral has to find the opening that holds it before the step means anything.
  constexpr double kSettleS = 1.0;
  for (long k = 0; k < samples(kSettleS, loop.period_s()); ++k) loop.sample(position_m);

  const double target = position_m + step_m;
  const double band = 0.02 * std::abs(step_m);
  const long n = samples(run_s, loop.period_s());
  const long tail_start = n - samples(kTailS, loop.period_s());
  double peak = position_m;  // the furthest excursion in the step's direction
  double last_outside_s = 0.0;
  double tail_min = INFINITY;
  double tail_max = -INFINITY;
  for (long k = 0; k < n; ++k) {
    loop.sample(target);
    // The position after the sample's rig steps, at time (k + 1)·T after the step.
    const double y = loop.position();
    const double t = static_cast<double>(k + 1) * loop.period_s();
    peak = step_m >= 0.0 ? std::max(peak, y) : std::min(peak, y);
    if (std::abs(y - target) > band) last_outside_s = t;
    if (k >= tail_start) {
      tail_min = std::min(tail_min, target - y);
      tail_max = std::max(tail_max, target - y);
    }
  }

  StepMetrics m;
  m.position_m = position_m;
  m.load_kg = load_kg;
  m.step_m = step_m;
  m.overshoot_pct = std::max(0.0, (peak - target) / step_m * 100.0);
  m.settling_s = last_outside_s;
  m.tail_peak_to_peak_m = tail_max - tail_min;
  m.tail_peak_to_peak_counts = m.tail_peak_to_peak_m / sim::SensorParameters{}.encoder_resolution_m;
  m.oscillating = m.tail_peak_to_peak_counts > kOscillationLimitCounts;
  return m;
}

StepSpread step_spread(const std::vector<StepMetrics>& cases) {
  StepSpread s;
  if (cases.empty()) return s;
  const auto [os_min, os_max] = std::minmax_element(
      cases.begin(), cases.end(), [](const StepMetrics& a, const StepMetrics& b) { return a.overshoot_pct < b.overshoot_pct; });
  const auto [ts_min, ts_max] = std::minmax_element(
      cases.begin(), cases.end(), [](const StepMetrics& a, const StepMetrics& b) { return a.settling_s < b.settling_s; });
  s.overshoot_spread_pts = os_max->overshoot_pct - os_min->overshoot_pct;
  s.settling_spread = ts_min->settling_s > 0.0 ? ts_max->settling_s / ts_min->settling_s - 1.0 : INFINITY;
  return s;
}

SineMetrics run_sine(double omega_rad_s, double load_kg, int periods, const control::PiParams& pi) {
  Lockstep loop(kSineCentreM, load_kg, pi);
  const double period = 2.0 * std::numbers::pi / omega_rad_s;
  const long n = samples(periods * period, loop.period_s());
  const long first_period = samples(period, loop.period_s());
  double max_error = 0.0;
  for (long k = 0; k < n; ++k) {
    const double e = loop.sample(sine_setpoint(omega_rad_s, loop.time_s()));
    // The first period holds the start-up transient: the reference starts at full speed 125·ω mm/s
    // from a rod at rest, which the paper also leaves out.
    if (k >= first_period) max_error = std::max(max_error, std::abs(e));
  }
  return {omega_rad_s, load_kg, periods, max_error};
}

DisturbanceMetrics run_disturbance(double base_load_kg, double added_kg, const control::PiParams& pi) {
  constexpr double kOmega = 0.5;
  Lockstep loop(kSineCentreM, base_load_kg, pi);
  const double period = 2.0 * std::numbers::pi / kOmega;
  const long first_period = samples(period, loop.period_s());
  const long add_at = samples(1.5 * period, loop.period_s());
  const long remove_at = samples(2.0 * period, loop.period_s());
  const long n = samples(4.0 * period, loop.period_s());
  // The last period starts a whole period after the removal, so it shows where the loop settled.
  const long last_period = n - first_period;

  DisturbanceMetrics m;
  m.base_load_kg = base_load_kg;
  m.added_kg = added_kg;
  m.add_s = static_cast<double>(add_at) * loop.period_s();
  m.remove_s = static_cast<double>(remove_at) * loop.period_s();
  for (long k = 0; k < n; ++k) {
    if (k == add_at) loop.set_load(base_load_kg + added_kg);
    if (k == remove_at) loop.set_load(base_load_kg);
    const double e = std::abs(loop.sample(sine_setpoint(kOmega, loop.time_s())));
    if (k >= first_period && k < add_at) m.baseline_error_m = std::max(m.baseline_error_m, e);
    if (k >= add_at && k < remove_at) m.added_peak_error_m = std::max(m.added_peak_error_m, e);
    if (k >= remove_at && k < last_period) m.removed_peak_error_m = std::max(m.removed_peak_error_m, e);
    if (k >= first_period) m.peak_error_m = std::max(m.peak_error_m, e);
    if (k >= last_period) m.final_error_m = std::max(m.final_error_m, e);
  }
  // Stable: a period after the load is back to base, the loop tracks as it did before the
  // disturbance (with a margin of 10 % plus 20 encoder counts for the stick-slip at the reversals).
  m.stable = std::isfinite(m.peak_error_m) && m.final_error_m <= 1.1 * m.baseline_error_m + 20e-6;
  return m;
}

HoldMetrics run_hold(double position_m, double load_kg, const control::PiParams& pi, double run_s) {
  Lockstep loop(position_m, load_kg, pi);
  const long n = samples(run_s, loop.period_s());
  const long window_start = n - samples(1.0, loop.period_s());
  double sum = 0.0;
  double max_abs = 0.0;
  for (long k = 0; k < n; ++k) {
    const double e = loop.sample(position_m);
    if (k >= window_start) {
      sum += e;
      max_abs = std::max(max_abs, std::abs(e));
    }
  }
  HoldMetrics m;
  m.position_m = position_m;
  m.load_kg = load_kg;
  m.kp = pi.kp;
  m.ki = pi.ki;
  m.mean_error_m = sum / static_cast<double>(n - window_start);
  m.max_abs_error_m = max_abs;
  return m;
}

}  // namespace hsa::analyze
