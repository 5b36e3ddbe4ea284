#include "tools/hsa_analyze/experiments.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "sim/rig.hpp"

namespace hsa::analyze {


namespace {

constexpr double kSineCentreM = 0.150;
constexpr double kSineAmplitudeM = 0.125;

// Columns of a cylinder experiment's trace. In direct mode the spool and current are NaN and the
// command is the opening.
const std::vector<std::string> kCylinderColumns{"t_s",     "setpoint_m",    "position_m",    "error_m",
                                                "opening", "command",       "pressure_a_pa", "pressure_b_pa",
                                                "spool_m", "current_a"};

// The rig under the cascade, advanced one PI sample (1 ms) at a time. Each of the sample's 10 rig
// steps starts with a cascade tick: the first runs the PI on the encoder, every one runs the valve
// loop on the LVDT in cascade mode; the command is written, then the rig steps. This is the order
// the daemon uses, with the output acting within the step it was computed in.
class Lockstep {
 public:
  Lockstep(double position_m, double load_kg, const Setup& setup)
      : rig_(config(position_m, load_kg, setup)), cascade_(cascade_params(setup)), trace_(setup.trace) {
    steps_per_sample_ = static_cast<int>(cascade_.params().valve_ticks_per_cylinder_tick);
    cascade_.activate(position(), spool());
  }

  [[nodiscard]] double position() const { return rig_.read().encoder_m.value; }
  [[nodiscard]] double spool() const { return rig_.read().spool_lvdt_m.value; }
  [[nodiscard]] double time_s() const { return rig_.time_s(); }
  [[nodiscard]] double period_s() const { return cascade_.params().cylinder.period_s; }
  void set_load(double kg) { rig_.set_load_mass(kg); }

  // One PI sample with this setpoint; returns the error the PI saw (setpoint − measured position).
  double sample(double setpoint_m) {
    const double error = setpoint_m - position();
    for (int i = 0; i < steps_per_sample_; ++i) {
      last_ = cascade_.tick({.rod_setpoint_m = setpoint_m, .rod_position_m = position(), .spool_position_m = spool()});
      rig_.set_valve_command(last_.command);
      rig_.step();
    }
    return error;
  }

  // Appends the state after the last sample to the trace, at time t_s (the caller's clock).
  void record(double t_s, double setpoint_m) {
    if (trace_ == nullptr) return;
    const sim::RigReadings r = rig_.read();
    const bool cascade = cascade_.params().drive == control::ValveDrive::proportional;
    trace_->add({t_s, setpoint_m, r.encoder_m.value, setpoint_m - r.encoder_m.value, last_.opening, last_.command,
                 r.pressure_a_pa.value, r.pressure_b_pa.value, cascade ? r.spool_lvdt_m.value : NAN,
                 cascade ? r.valve_current_a.value : NAN});
  }

  void begin_trace(const std::string& label) {
    if (trace_ != nullptr) trace_->begin(label, kCylinderColumns);
  }

 private:
  static sim::RigConfig config(double position_m, double load_kg, const Setup& setup) {
    sim::RigConfig c = setup.rig;
    c.valve = setup.drive == Drive::direct ? sim::ValveKind::servo : sim::ValveKind::proportional;
    c.initial_position_m = position_m;
    c.load_kg = load_kg;
    if (setup.noiseless_lvdt) {
      c.sensors.lvdt.ripple_amplitude_m = {0.0, 0.0, 0.0};
      c.sensors.lvdt.noise_density_m_per_sqrt_hz = 0.0;
    }
    return c;
  }

  static control::CascadeParams cascade_params(const Setup& s) {
    control::CascadeParams p;
    p.cylinder = s.pi;
    p.drive = s.drive == Drive::direct ? control::ValveDrive::direct : control::ValveDrive::proportional;
    p.valve = s.valve;
    p.valve_ticks_per_cylinder_tick = static_cast<std::uint32_t>(std::lround(s.pi.period_s / s.valve.period_s));
    return p;
  }

  sim::Rig rig_;
  control::Cascade cascade_;
  Trace* trace_;
  control::LawOutput last_{};
  int steps_per_sample_ = 10;
};

// Number of PI samples covering duration_s.
long samples(double duration_s, double period_s) { return std::lround(duration_s / period_s); }

double sine_setpoint(double omega_rad_s, double t_s) {
  return kSineCentreM + kSineAmplitudeM * std::sin(omega_rad_s * t_s);
}

// Every how many samples a long run records, so that a trace stays near 5000 rows per case.
long trace_stride(long samples_in_run) { return std::max(1L, samples_in_run / 5000); }

}  // namespace

std::string label_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

StepMetrics run_step(double position_m, double load_kg, const Setup& setup, double step_m, double record_s) {
  Lockstep loop(position_m, load_kg, setup);
  loop.begin_trace(step_label(position_m, load_kg));
  // Settle first: the rod starts at rest, but the load has to be taken up by the chamber pressures
  // and the integral has to find the opening that holds it before the step means anything.
  constexpr double kSettleS = 1.0;
  for (long k = 0; k < samples(kSettleS, loop.period_s()); ++k) loop.sample(position_m);

  const double target = position_m + step_m;
  const double band = 0.02 * std::abs(step_m);
  const long n = samples(kStepHoldS, loop.period_s());
  const long recorded = samples(record_s, loop.period_s());
  const long rest_start = n - samples(kRestWindowS, loop.period_s());
  double peak = position_m;  // the furthest excursion in the step's direction
  double last_outside_s = 0.0;
  double rest_min = INFINITY;
  double rest_max = -INFINITY;
  double rest_sum = 0.0;
  for (long k = 0; k < n; ++k) {
    loop.sample(target);
    // The position after the sample's rig steps, at time (k + 1)·T after the step.
    const double y = loop.position();
    const double t = static_cast<double>(k + 1) * loop.period_s();
    if (k < recorded) loop.record(t, target);
    peak = step_m >= 0.0 ? std::max(peak, y) : std::min(peak, y);
    if (std::abs(y - target) > band) last_outside_s = t;
    if (k >= rest_start) {
      rest_min = std::min(rest_min, target - y);
      rest_max = std::max(rest_max, target - y);
      rest_sum += target - y;
    }
  }

  StepMetrics m;
  m.position_m = position_m;
  m.load_kg = load_kg;
  m.step_m = step_m;
  m.overshoot_pct = std::max(0.0, (peak - target) / step_m * 100.0);
  m.settling_s = last_outside_s;
  m.rest_peak_to_peak_m = rest_max - rest_min;
  m.rest_peak_to_peak_counts = m.rest_peak_to_peak_m / setup.rig.sensors.encoder_resolution_m;
  m.rest_error_m = rest_sum / static_cast<double>(n - rest_start);
  m.oscillating = m.rest_peak_to_peak_counts > kOscillationLimitCounts;
  return m;
}

std::string step_label(double position_m, double load_kg) {
  return label_number(position_m * 1e3) + "mm_" + label_number(load_kg) + "kg";
}

void trace_predicted_step(Trace& trace, const std::string& label, double position_m, double step_m,
                          double period_s, const std::vector<double>& unit_response) {
  trace.begin(label, kCylinderColumns);
  const double target = position_m + step_m;
  for (std::size_t k = 0; k < unit_response.size(); ++k) {
    const double y = position_m + step_m * unit_response[k];
    trace.add({static_cast<double>(k + 1) * period_s, target, y, target - y, NAN, NAN, NAN, NAN, NAN, NAN});
  }
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

SineMetrics run_sine(double omega_rad_s, double load_kg, int periods, const Setup& setup) {
  Lockstep loop(kSineCentreM, load_kg, setup);
  loop.begin_trace("w" + label_number(omega_rad_s) + "_" + label_number(load_kg) + "kg");
  const double period = 2.0 * std::numbers::pi / omega_rad_s;
  const long n = samples(periods * period, loop.period_s());
  const long first_period = samples(period, loop.period_s());
  const long stride = trace_stride(n);
  double max_error = 0.0;
  for (long k = 0; k < n; ++k) {
    const double t = loop.time_s();
    const double setpoint = sine_setpoint(omega_rad_s, t);
    const double e = loop.sample(setpoint);
    // The trace pairs the setpoint with the position after the sample, as the step's does.
    if (k % stride == 0) loop.record(t, setpoint);
    // The first period holds the start-up transient: the reference starts at full speed 125·ω mm/s
    // from a rod at rest, which the paper also leaves out.
    if (k >= first_period) max_error = std::max(max_error, std::abs(e));
  }
  return {omega_rad_s, load_kg, periods, max_error};
}

DisturbanceMetrics run_disturbance(double base_load_kg, double added_kg, const Setup& setup, double change_s) {
  if (!(change_s >= 0.0)) throw std::invalid_argument("disturbance: the load change time must be >= 0 s");
  constexpr double kOmega = 0.5;
  Lockstep loop(kSineCentreM, base_load_kg, setup);
  loop.begin_trace(label_number(base_load_kg) + "kg_plus_" + label_number(added_kg) + "kg");
  const double period = 2.0 * std::numbers::pi / kOmega;
  const long first_period = samples(period, loop.period_s());
  const long add_at = samples(1.5 * period, loop.period_s());
  const long remove_at = samples(2.0 * period, loop.period_s());
  const long n = samples(4.0 * period, loop.period_s());
  // The last period starts a whole period after the removal, so it shows where the loop settled.
  const long last_period = n - first_period;
  const long stride = trace_stride(n);

  DisturbanceMetrics m;
  m.base_load_kg = base_load_kg;
  m.added_kg = added_kg;
  m.change_s = change_s;
  m.add_s = static_cast<double>(add_at) * loop.period_s();
  m.remove_s = static_cast<double>(remove_at) * loop.period_s();
  for (long k = 0; k < n; ++k) {
    // The weight's share carried by the rod ramps over change_s from each change's start (a step
    // when change_s is 0).
    const auto share = [&](long start) {
      if (k < start) return 0.0;
      const double t = static_cast<double>(k - start + 1) * loop.period_s();
      return change_s > 0.0 ? std::min(1.0, t / change_s) : 1.0;
    };
    loop.set_load(base_load_kg + added_kg * (share(add_at) - share(remove_at)));
    const double t = loop.time_s();
    const double setpoint = sine_setpoint(kOmega, t);
    const double e = std::abs(loop.sample(setpoint));
    if (k % stride == 0) loop.record(t, setpoint);
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

HoldMetrics run_hold(double position_m, double load_kg, const Setup& setup, double run_s) {
  Lockstep loop(position_m, load_kg, setup);
  loop.begin_trace(label_number(position_m * 1e3) + "mm_" + label_number(load_kg) + "kg_" +
                   (setup.pi.ki > 0.0 ? "PI" : "P"));
  const long n = samples(run_s, loop.period_s());
  const long window_start = n - samples(1.0, loop.period_s());
  double sum = 0.0;
  double max_abs = 0.0;
  for (long k = 0; k < n; ++k) {
    const double e = loop.sample(position_m);
    if (k % 10 == 0) loop.record(static_cast<double>(k + 1) * loop.period_s(), position_m);
    if (k >= window_start) {
      sum += e;
      max_abs = std::max(max_abs, std::abs(e));
    }
  }
  HoldMetrics m;
  m.position_m = position_m;
  m.load_kg = load_kg;
  m.kp = setup.pi.kp;
  m.ki = setup.pi.ki;
  m.mean_error_m = sum / static_cast<double>(n - window_start);
  m.max_abs_error_m = max_abs;
  return m;
}

// ---- Trace ----

void Trace::begin(const std::string& label, const std::vector<std::string>& columns) {
  if (!columns_.empty() && columns != columns_) throw std::logic_error("Trace: all cases must use the same columns");
  columns_ = columns;
  labels_.push_back(label);
}

void Trace::add(const std::vector<double>& values) {
  if (labels_.empty() || values.size() != columns_.size())
    throw std::logic_error("Trace: add() needs a begin() and one value per column");
  rows_.push_back({labels_.size() - 1, values});
}

void Trace::write_csv(const std::string& path) const {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + path);
  std::fprintf(f, "case");
  for (const std::string& c : columns_) std::fprintf(f, ",%s", c.c_str());
  std::fprintf(f, "\n");
  for (const Row& row : rows_) {
    std::fprintf(f, "%s", labels_[row.label].c_str());
    // %.9g keeps the encoder's 1 µm and the LVDT's sub-µm noise at any magnitude of the columns.
    for (double v : row.values) std::fprintf(f, ",%.9g", v);
    std::fprintf(f, "\n");
  }
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw std::runtime_error("error writing " + path);
}

const char* drive_name(Drive drive) { return drive == Drive::direct ? "direct" : "cascade"; }

}  // namespace hsa::analyze
