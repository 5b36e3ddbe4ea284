#include "tools/hsa_analyze/valve_experiments.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "control/state_predictor.hpp"
#include "control/valve_model_predictor.hpp"
#include "sim/rig.hpp"

namespace hsa::analyze {

namespace {

const std::vector<std::string> kValveColumns{"t_s",     "reference_m",         "spool_m",  "error_m",
                                             "command_a", "current_a", "opening"};

// The proportional valve under the valve loop alone: every rig step (100 µs) starts with one
// predictor + law sample on the LVDT, as the cascade does in its ticks. The predictor is the
// paper's (Table 2), or the one driven by the identified model when the law's settings ask for it.
class ValveLoop {
 public:
  ValveLoop(const control::ValveLawParams& valve, const sim::ProportionalValveParameters& plant,
            std::uint64_t rig_seed)
      : rig_(config(plant, rig_seed)),
        predictor_(control::predictor_gains(control::kTable2Gamma), valve.period_s),
        law_(valve) {
    if (std::abs(valve.period_s - rig_.config().step_s) > 1e-12)
      throw std::invalid_argument("valve experiment: the valve loop must run at the rig's step");
    predictor_.reset(spool());
    if (valve.model_predictor.enabled) {
      model_predictor_.emplace(valve.model_predictor, valve.period_s);
      model_predictor_->reset(spool());
    }
    if (valve.predictive.enabled) predictive_.emplace(valve.predictive);
  }

  [[nodiscard]] double spool() const { return rig_.read().spool_lvdt_m.value; }
  [[nodiscard]] double period_s() const { return rig_.config().step_s; }

  // One tick with this reference; returns the LVDT after the rig step.
  double tick(double reference_m) {
    const double y = spool();
    if (predictive_) {
      command_ = predictive_->update(reference_m, y);
    } else {
      command_ = law_.update(reference_m, model_predictor_ ? model_predictor_->update(y) : predictor_.update(y));
      if (model_predictor_) model_predictor_->commanded(command_);
    }
    rig_.set_valve_command(command_);
    rig_.step();
    return spool();
  }

  void record(Trace* trace, double t_s, double reference_m) const {
    if (trace == nullptr) return;
    const sim::RigReadings r = rig_.read();
    trace->add({t_s, reference_m, r.spool_lvdt_m.value, reference_m - r.spool_lvdt_m.value, command_,
                r.valve_current_a.value, rig_.valve_opening()});
  }

 private:
  static sim::RigConfig config(const sim::ProportionalValveParameters& plant, std::uint64_t rig_seed) {
    sim::RigConfig c;
    c.seed = rig_seed;
    c.valve = sim::ValveKind::proportional;
    c.proportional_valve = plant;
    c.initial_position_m = 0.150;
    return c;
  }

  sim::Rig rig_;
  control::StatePredictor predictor_;
  std::optional<control::ValveModelPredictor> model_predictor_;
  control::ValveLaw law_;
  std::optional<control::ValvePredictiveLaw> predictive_;
  double command_ = 0.0;
};

// Reference shapes of unit amplitude, starting at 0 at t = 0 (the square at +1).
double triangle(double frequency_hz, double t_s) {
  const double p = t_s * frequency_hz - std::floor(t_s * frequency_hz);
  if (p < 0.25) return 4.0 * p;
  if (p < 0.75) return 2.0 - 4.0 * p;
  return 4.0 * p - 4.0;
}
double square(double frequency_hz, double t_s) {
  const double p = t_s * frequency_hz - std::floor(t_s * frequency_hz);
  return p < 0.5 ? 1.0 : -1.0;
}

// A run of whole periods: `settle` unscored, then `score` scored. Returns the scored samples as
// (time, measured) pairs: the reference of tick k is r(k·T), the LVDT read after its step belongs
// to (k + 1)·T.
struct Samples {
  std::vector<double> t;
  std::vector<double> y;
};

template <class Reference>
Samples run_valve(const control::ValveLawParams& valve, const sim::ProportionalValveParameters& plant,
                  double frequency_hz, int settle, int score, Reference r, Trace* trace, const std::string& label,
                  std::uint64_t rig_seed) {
  ValveLoop loop(valve, plant, rig_seed);
  settle += valve.learning_settle_periods;  // a learning law learns before it is scored
  const double T = loop.period_s();
  const long n_settle = std::lround(settle / frequency_hz / T);
  const long n = n_settle + std::lround(score / frequency_hz / T);
  // Traces keep the scored periods, at most about 4000 rows.
  const long stride = std::max(1L, (n - n_settle) / 4000);
  if (trace != nullptr) trace->begin(label, kValveColumns);
  Samples s;
  s.t.reserve(static_cast<std::size_t>(n - n_settle));
  s.y.reserve(static_cast<std::size_t>(n - n_settle));
  for (long k = 0; k < n; ++k) {
    const double reference = r(static_cast<double>(k) * T);
    const double y = loop.tick(reference);
    const double t = static_cast<double>(k + 1) * T;
    if (k >= n_settle) {
      s.t.push_back(t);
      s.y.push_back(y);
      // Trace times start at the scored window; the reference is the one at the same instant.
      if ((k - n_settle) % stride == 0) loop.record(trace, t - n_settle * T, r(t));
    }
  }
  return s;
}

}  // namespace

ValveTriangleMetrics run_valve_triangle(double fraction, double frequency_hz, const control::ValveLawParams& valve,
                                        const sim::ProportionalValveParameters& plant, Trace* trace, std::uint64_t rig_seed) {
  const double a = fraction * kValveStrokeM;
  const auto r = [&](double t) { return a * triangle(frequency_hz, t); };
  const Samples s = run_valve(valve, plant, frequency_hz, 2, 4, r, trace,
                              "triangle" + label_number(fraction * 100) + "_" + label_number(frequency_hz) + "Hz", rig_seed);
  // Least-squares delay over a 0.01 ms grid from 0 to 20 ms: the triangle's corners make the fit
  // sharp, and the grid is ten times finer than a sample.
  ValveTriangleMetrics m{.fraction = fraction, .frequency_hz = frequency_hz};
  double best = INFINITY;
  for (int j = 0; j <= 2000; ++j) {
    const double tau = j * 1e-5;
    double sum = 0.0;
    for (std::size_t k = 0; k < s.t.size(); ++k) sum += std::pow(s.y[k] - r(s.t[k] - tau), 2);
    if (sum < best) {
      best = sum;
      m.delay_s = tau;
    }
  }
  std::vector<double> eta(s.t.size());
  double sum = 0.0;
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    eta[k] = s.y[k] - r(s.t[k] - m.delay_s);
    m.residual_max_m = std::max(m.residual_max_m, std::abs(eta[k]));
    sum += eta[k] * eta[k];
  }
  const double n = static_cast<double>(s.t.size());
  m.residual_rms_m = std::sqrt(sum / n);
  // The scored samples are whole periods of the reference, `periods` of `period` samples each.
  const std::size_t period = static_cast<std::size_t>(std::lround(1.0 / (frequency_hz * valve.period_s)));
  const std::size_t periods = eta.size() / period;
  std::vector<double> mean(period, 0.0);
  for (std::size_t k = 0; k < periods * period; ++k) mean[k % period] += eta[k] / static_cast<double>(periods);
  double repeating = 0.0, rest = 0.0;
  for (std::size_t k = 0; k < periods * period; ++k) {
    const double d = eta[k] - mean[k % period];
    m.repeating_max_m = std::max(m.repeating_max_m, std::abs(mean[k % period]));
    m.nonrepeating_max_m = std::max(m.nonrepeating_max_m, std::abs(d));
    repeating += mean[k % period] * mean[k % period];
    rest += d * d;
  }
  m.repeating_rms_m = std::sqrt(repeating / static_cast<double>(periods * period));
  m.nonrepeating_rms_m = std::sqrt(rest / static_cast<double>(periods * period));
  return m;
}

ValveSineMetrics run_valve_sine(double fraction, double frequency_hz, const control::ValveLawParams& valve,
                                const sim::ProportionalValveParameters& plant, Trace* trace, std::uint64_t rig_seed) {
  const double a = fraction * kValveStrokeM;
  const double w = 2.0 * std::numbers::pi * frequency_hz;
  // At least 0.1 s to settle (the integrator's transient) and 0.1 s scored, in whole periods.
  const int settle = std::max(3, static_cast<int>(std::ceil(0.1 * frequency_hz)));
  const int score = std::max(2, static_cast<int>(std::ceil(0.1 * frequency_hz)));
  const Samples s = run_valve(valve, plant, frequency_hz, settle, score, [&](double t) { return a * std::sin(w * t); }, trace,
                              "sine" + label_number(fraction * 100) + "_" + label_number(frequency_hz) + "Hz", rig_seed);
  // Least squares y ≈ p·sin(ωt) + q·cos(ωt) + c: the offset c keeps a small static error out of
  // the gain.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    const Eigen::Vector3d row(std::sin(w * s.t[k]), std::cos(w * s.t[k]), 1.0);
    ata += row * row.transpose();
    aty += row * s.y[k];
  }
  const Eigen::Vector3d pqc = ata.ldlt().solve(aty);
  ValveSineMetrics m{.fraction = fraction, .frequency_hz = frequency_hz};
  m.gain_db = 20.0 * std::log10(std::hypot(pqc(0), pqc(1)) / a);
  // y = G·sin(ωt + φ): p = G cos φ, q = G sin φ. Lags of up to 270° stay negative.
  double phase = std::atan2(pqc(1), pqc(0));
  if (phase > std::numbers::pi / 2) phase -= 2.0 * std::numbers::pi;
  m.phase_deg = phase * 180.0 / std::numbers::pi;
  m.delay_s = -phase / w;
  return m;
}

double minus_3db_frequency_hz(const std::vector<ValveSineMetrics>& sweep) {
  for (std::size_t i = 0; i < sweep.size(); ++i) {
    if (sweep[i].gain_db >= -3.0) continue;
    if (i == 0) return sweep[0].frequency_hz;
    const ValveSineMetrics& lo = sweep[i - 1];
    const ValveSineMetrics& hi = sweep[i];
    return lo.frequency_hz + (hi.frequency_hz - lo.frequency_hz) * (-3.0 - lo.gain_db) / (hi.gain_db - lo.gain_db);
  }
  return INFINITY;
}

ValveSquareMetrics run_valve_square(double fraction, double frequency_hz, const control::ValveLawParams& valve,
                                    const sim::ProportionalValveParameters& plant, Trace* trace, std::uint64_t rig_seed) {
  const double a = fraction * kValveStrokeM;
  const auto r = [&](double t) { return a * square(frequency_hz, t); };
  const Samples s = run_valve(valve, plant, frequency_hz, 2, 4, r, trace,
                              "square" + label_number(fraction * 100) + "_" + label_number(frequency_hz) + "Hz", rig_seed);
  ValveSquareMetrics m{.fraction = fraction, .frequency_hz = frequency_hz};
  // Each half period of the scored window starts with a transition of 2a towards r = ±a.
  const double half = 0.5 / frequency_hz;
  const double t0 = s.t.front() - (s.t[1] - s.t[0]);  // the window starts on a transition
  double rise_sum = 0.0;
  int transitions = 0;
  for (int h = 0; h < 8; ++h) {
    const double start = t0 + h * half;
    const double target = r(start + 0.5 * half);
    const double sign = target > 0.0 ? 1.0 : -1.0;
    // Progress from the previous level (0) to the target (1).
    double t10 = NAN;
    double t90 = NAN;
    double peak = -INFINITY;
    double last = -INFINITY;
    bool arrived = false;
    for (std::size_t k = 0; k < s.t.size(); ++k) {
      if (s.t[k] <= start || s.t[k] > start + half) continue;
      const double progress = (sign * s.y[k] + a) / (2.0 * a);
      if (std::isnan(t10) && progress >= 0.1) t10 = s.t[k];
      if (std::isnan(t90) && progress >= 0.9) t90 = s.t[k];
      if (!std::isnan(t90) && progress < last) arrived = true;
      if (arrived && s.t[k] <= start + 0.5 * half)
        m.arrival_error_m = std::max(m.arrival_error_m, std::abs(target - s.y[k]));
      last = progress;
      peak = std::max(peak, progress);
      if (s.t[k] > start + 0.5 * half) m.settled_error_m = std::max(m.settled_error_m, std::abs(target - s.y[k]));
    }
    m.overshoot_pct = std::max(m.overshoot_pct, (peak - 1.0) * 100.0);
    if (std::isnan(t90)) {
      // Never reached 90 %: no slew rate can be claimed for this wave.
      rise_sum = INFINITY;
    } else {
      rise_sum += t90 - t10;
    }
    ++transitions;
  }
  m.rise_10_90_s = rise_sum / transitions;
  m.slew_rate_m_s = 0.8 * 2.0 * a / m.rise_10_90_s;
  return m;
}

namespace {

// 10–90 % time of the open-loop move from -sign·a to sign·a at the constant reference `current_a`.
double full_effort_rise_s(const sim::ProportionalValveParameters& parameters, double a, double sign, double current_a) {
  constexpr double kStepS = 1e-5;
  sim::ProportionalValve valve(parameters, kStepS);
  valve.reset(-sign * a);
  double t10 = NAN;
  for (long k = 1; k <= 200000; ++k) {  // 2 s: far beyond any transition
    valve.step(current_a);
    const double progress = (sign * valve.position() + a) / (2.0 * a);
    if (std::isnan(t10) && progress >= 0.1) t10 = k * kStepS;
    if (progress >= 0.9) return k * kStepS - t10;
  }
  return INFINITY;  // the full effort does not reach 90 %
}

}  // namespace

ValveSlewBound valve_slew_bound(double fraction, const sim::ProportionalValveParameters& valve) {
  const double a = fraction * kValveStrokeM;
  ValveSlewBound b;
  b.rise_up_s = full_effort_rise_s(valve, a, 1.0, valve.current_max_a);
  b.rise_down_s = full_effort_rise_s(valve, a, -1.0, 0.0);
  b.slew_rate_m_s = 0.8 * 2.0 * a / (0.5 * (b.rise_up_s + b.rise_down_s));
  return b;
}

}  // namespace hsa::analyze
