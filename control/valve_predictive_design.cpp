#include "control/valve_predictive_design.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "control/command_delay_line.hpp"
#include "control/valve_triangle_residual.hpp"

namespace hsa::control {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kMicrometres = 1e6;  // the QP's cost in µm², its commands in A
constexpr int kMaxRiccatiIterations = 200000;

// The steady state of X ← f(X), started from `x`, once the largest relative change is below 1e-12.
template <class Step>
MatrixXd settle(MatrixXd x, Step step, const char* what) {
  for (int it = 0; it < kMaxRiccatiIterations; ++it) {
    MatrixXd next = step(x);
    next = 0.5 * (next + next.transpose());
    const double scale = std::max(next.cwiseAbs().maxCoeff(), 1e-300);
    const double change = (next - x).cwiseAbs().maxCoeff() / scale;
    x = std::move(next);
    if (change < 1e-12) return x;
  }
  throw std::invalid_argument(std::string("valve_predictive_params: the ") + what + " Riccati recursion did not settle");
}

void check(const ValvePredictiveValve& v, double period_s, const ValvePredictiveSettings& s) {
  const identification::ValveModel& m = v.model;
  if (!(period_s > 0.0) || !(m.gain_m_per_a > 0.0) || !(m.natural_frequency_hz > 0.0) || !(m.damping_ratio > 0.0) ||
      !(m.magnetic_lag_s > 0.0) || !(m.width_a >= 0.0) || !(m.friction_band_m >= 0.0) || !(m.delay_s >= 0.0) ||
      !(m.sensor_bandwidth_hz > 0.0) || !std::isfinite(m.rest_position_m) || !(v.regulator_delay_s >= period_s) ||
      !(v.current_max_a > 0.0) || !(v.lvdt_noise_m > 0.0))
    throw std::invalid_argument(
        "valve_predictive_params: T, g, f0, ζ, τa, the LVDT's bandwidth, I_max and the noise must be > 0, w, s_f and δ "
        ">= 0, and the regulator's delay at least one period");
  if (s.preview_samples < 1 || s.horizon_extra_samples < 1 || !(s.rate_weight_m2_per_a2 > 0.0) ||
      !(s.dither_fraction >= 0.0) || !(s.headroom_fraction >= 0.0 && s.headroom_fraction <= 1.0) ||
      !(s.disturbance_walk_a > 0.0) || !(s.held_disturbance_walk_a > 0.0) || !(s.velocity_walk_m_s > 0.0) ||
      !(s.direction_velocity_m_s > 0.0) || s.max_qp_iterations < 1)
    throw std::invalid_argument(
        "valve_predictive_params: P, H − P and the QP's iterations must be >= 1, ρ, the random walks and v_d > 0, the "
        "dither's share >= 0, the headroom's share in [0, 1]");
}

}  // namespace

ValvePredictiveValve predictive_valve(const identification::ValveFit& fit, double current_max_a) {
  ValvePredictiveValve v;
  v.model = fit.model;
  v.regulator_delay_s = fit.regulator.delay_s;
  v.current_max_a = identification::identified_valve(fit, current_max_a).current_max_a;
  return v;
}

ValvePredictiveParams valve_predictive_params(const ValvePredictiveValve& valve, double period_s, double dither_frequency_hz,
                                              const ValvePredictiveSettings& s) {
  check(valve, period_s, s);
  const identification::ValveModel& m = valve.model;
  const double T = period_s;
  const int delay = static_cast<int>(std::lround((valve.regulator_delay_s + m.delay_s) / T)) - 1;
  if (delay < 1 || delay > CommandDelayLine::kMaxSamples)
    throw std::invalid_argument("valve_predictive_params: the delay τ + δ must lie between 2 and " +
                                std::to_string(CommandDelayLine::kMaxSamples + 1) + " periods");
  ValvePredictiveParams p;
  p.enabled = true;
  p.period_s = T;
  p.delay_samples = delay;
  p.preview_samples = s.preview_samples;
  p.horizon_samples = s.preview_samples + s.horizon_extra_samples;
  p.current_max_a = valve.current_max_a;
  p.dither_amplitude_a = s.dither_fraction * m.width_a;
  if (p.dither_amplitude_a > 0.0) {
    const double half = 0.5 / (dither_frequency_hz * T);
    if (!(dither_frequency_hz > 0.0) || std::abs(half - std::round(half)) > 1e-6 || std::round(half) < 1.0)
      throw std::invalid_argument("valve_predictive_params: the dither's frequency must be 1/(2·n·T) for a whole n >= 1");
    p.dither_half_period_samples = static_cast<int>(std::lround(half));
  }
  // The box keeps `headroom_fraction` of the dither off 0 and I_max: a command nearer a limit has
  // its dither cut there, and the play's mean moves off the model's w/2 by up to half the cut.
  p.lower_a = s.headroom_fraction * p.dither_amplitude_a;
  p.upper_a = valve.current_max_a - s.headroom_fraction * p.dither_amplitude_a;
  if (!(p.lower_a < p.upper_a))
    throw std::invalid_argument("valve_predictive_params: the dither leaves no current between 0 and I_max");
  p.direction_velocity_m_s = s.direction_velocity_m_s;
  p.gain_m_per_a = m.gain_m_per_a;
  p.rest_position_m = m.rest_position_m;
  p.mean_play_a = 0.5 * m.width_a;
  p.max_qp_iterations = s.max_qp_iterations;

  // The continuous model with its two inputs (the delayed command, φ) as states of zero slope.
  const double w0 = 2.0 * std::numbers::pi * m.natural_frequency_hz;
  const double tau_s = 1.0 / (2.0 * std::numbers::pi * m.sensor_bandwidth_hz);
  MatrixXd a = MatrixXd::Zero(8, 8);
  a(kForce, kForce) = -1.0 / m.magnetic_lag_s;
  a(kForce, kDisturbance) = 1.0 / m.magnetic_lag_s;
  a(kForce, kOne) = -p.mean_play_a / m.magnetic_lag_s;
  a(kForce, 6) = 1.0 / m.magnetic_lag_s;
  a(kPosition, kVelocity) = 1.0;
  a(kVelocity, kForce) = w0 * w0 * m.gain_m_per_a;
  a(kVelocity, kPosition) = -w0 * w0;
  a(kVelocity, kVelocity) = -2.0 * m.damping_ratio * w0;
  a(kVelocity, kOne) = w0 * w0 * m.rest_position_m;
  a(kVelocity, 7) = -w0 * w0 * m.friction_band_m;
  a(kReading, kPosition) = 1.0 / tau_s;
  a(kReading, kReading) = -1.0 / tau_s;
  const MatrixXd e = (a * T).exp();

  // The plant: the six states and the commands still in the delay line, I(i−1) … I(i−D).
  const int np = kValvePredictiveFixedStates + delay;
  MatrixXd ap = MatrixXd::Zero(np, np);
  VectorXd bp = VectorXd::Zero(np), fp = VectorXd::Zero(np);
  ap.topLeftCorner(6, 6) = e.topLeftCorner(6, 6);
  ap.block(0, np - 1, 6, 1) = e.block(0, 6, 6, 1);  // I(i−D) enters the valve over this period
  fp.head(6) = e.block(0, 7, 6, 1);
  bp(6) = 1.0;
  for (int j = 7; j < np; ++j) ap(j, j - 1) = 1.0;

  // The Kalman gains (the correction with the reading), from the filter's Riccati recursion: one
  // for a moving target, one with the held target's faster disturbance walk.
  const double reading_var = valve.lvdt_noise_m * valve.lvdt_noise_m;
  const auto kalman_gain = [&](double disturbance_walk_a) {
    MatrixXd noise = MatrixXd::Zero(np, np);
    noise(kDisturbance, kDisturbance) = disturbance_walk_a * disturbance_walk_a;
    noise(kVelocity, kVelocity) = s.velocity_walk_m_s * s.velocity_walk_m_s;
    const auto corrected = [&](const MatrixXd& pk) {
      const VectorXd pc = pk.col(kReading);
      return MatrixXd(pk - pc * pc.transpose() / (pk(kReading, kReading) + reading_var));
    };
    MatrixXd p0 = MatrixXd::Zero(np, np);
    p0(kDisturbance, kDisturbance) = 1.0;
    const MatrixXd prior = settle(
        p0, [&](const MatrixXd& pk) { return MatrixXd(ap * corrected(pk) * ap.transpose() + noise); }, "filter's");
    return VectorXd(prior.col(kReading) / (prior(kReading, kReading) + reading_var));
  };
  const VectorXd gain = kalman_gain(s.disturbance_walk_a);
  const VectorXd held_gain = kalman_gain(s.held_disturbance_walk_a);

  // The plant with the reference register ξ = r(i−P … i) and φ's, each shifted, the last held.
  const int P = s.preview_samples, nr = P + 1, n = np + 2 * nr;
  MatrixXd aa = MatrixXd::Zero(n, n);
  VectorXd ba = VectorXd::Zero(n);
  aa.topLeftCorner(np, np) = ap;
  aa.block(0, np + nr, np, 1) = fp;  // φ(i) acts over this period
  ba.head(np) = bp;
  for (int r0 : {np, np + nr}) {
    for (int j = 0; j < P; ++j) aa(r0 + j, r0 + j + 1) = 1.0;
    aa(r0 + P, r0 + P) = 1.0;
  }
  // Stage cost zᵀQz + 2zᵀN·I + R·I², in µm²: (y − ξ_0)² + ρ·(I − I(i−1))².
  VectorXd tracking = VectorXd::Zero(n), previous = VectorXd::Zero(n);
  tracking(kReading) = kMicrometres;
  tracking(np) = -kMicrometres;
  previous(6) = 1.0;
  const double rho = s.rate_weight_m2_per_a2 * kMicrometres * kMicrometres;
  const MatrixXd q = tracking * tracking.transpose() + rho * previous * previous.transpose();
  const VectorXd cross = -rho * previous;
  const double r = rho;
  const MatrixXd cost_to_go = settle(
      q,
      [&](const MatrixXd& sk) {
        const VectorXd sb = sk * ba;
        const VectorXd k = aa.transpose() * sb + cross;
        return MatrixXd(q + aa.transpose() * sk * aa - k * k.transpose() / (r + ba.dot(sb)));
      },
      "control");

  // The QP over H commands: x_j = A^j·x0 + Σ_{i<j} A^{j−1−i}·B·I_i.
  const int h = p.horizon_samples;
  std::vector<MatrixXd> power(static_cast<std::size_t>(h) + 1);
  power[0] = MatrixXd::Identity(n, n);
  for (int j = 1; j <= h; ++j) power[static_cast<std::size_t>(j)] = aa * power[static_cast<std::size_t>(j) - 1];
  MatrixXd hessian = MatrixXd::Zero(h, h), linear = MatrixXd::Zero(h, n);
  for (int j = 1; j <= h; ++j) {
    const MatrixXd& qj = j == h ? cost_to_go : q;
    MatrixXd g(n, j);
    for (int i = 0; i < j; ++i) g.col(i) = power[static_cast<std::size_t>(j - 1 - i)] * ba;
    const MatrixXd qg = qj * g;
    hessian.topLeftCorner(j, j) += g.transpose() * qg;
    linear.topRows(j) += qg.transpose() * power[static_cast<std::size_t>(j)];
    if (j < h) {
      const VectorXd c = g.transpose() * cross;  // I_i (i < j) with I_j
      for (int i = 0; i < j; ++i) {
        hessian(i, j) += c(i);
        hessian(j, i) += c(i);
      }
    }
  }
  for (int i = 0; i < h; ++i) {
    hessian(i, i) += r;
    linear.row(i) += cross.transpose() * power[static_cast<std::size_t>(i)];
  }

  const auto row_major = [](const MatrixXd& x) {
    std::vector<double> v(static_cast<std::size_t>(x.size()));
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v.data(), x.rows(), x.cols()) = x;
    return v;
  };
  p.transition = row_major(ap);
  p.input.assign(bp.data(), bp.data() + np);
  p.friction.assign(fp.data(), fp.data() + np);
  p.kalman_gain.assign(gain.data(), gain.data() + np);
  p.held_kalman_gain.assign(held_gain.data(), held_gain.data() + np);
  p.held_band_m = valve.lvdt_noise_m;
  p.qp_hessian = row_major(hessian);
  p.qp_linear = row_major(linear);
  return p;
}

double predictive_triangle_peak(const ValvePredictiveValve& valve, const ValvePredictiveParams& law, std::uint64_t seed) {
  const identification::ValveModel& m = valve.model;
  const double T = law.period_s;
  const int shift = std::max(0, static_cast<int>(std::lround(valve.regulator_delay_s / T)) - 1);
  const long period = std::lround(1.0 / (kDesignTriangleFrequencyHz * T));
  const long settle = 2 * period, n = settle + 4 * period;
  ValvePredictiveLaw l(law);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, valve.lvdt_noise_m);
  identification::ValveModelState state = identification::rest_state(m, 0.0);
  double reading = state.sensor_m + noise(rng);
  std::vector<double> commands, currents, t, y;
  std::vector<identification::ValveModelState> states;
  commands.reserve(static_cast<std::size_t>(n));
  currents.reserve(static_cast<std::size_t>(n) + 1);
  for (long k = 0; k < n; ++k) {
    const double r = kDesignTriangleAmplitudeM * unit_triangle(kDesignTriangleFrequencyHz, static_cast<double>(k) * T);
    commands.push_back(l.update(r, reading));
    // The current measured over period k: the command `shift` periods before (eq 1's τ).
    currents.push_back(commands[static_cast<std::size_t>(std::max(0L, k - shift))]);
    currents.push_back(currents.back());  // not yet used: δ is at least a substep
    (void)identification::simulate_valve(m, currents, T, state, static_cast<std::size_t>(k), static_cast<std::size_t>(k) + 2,
                                         &states);
    currents.pop_back();
    state = states[1];
    reading = state.sensor_m + noise(rng);
    if (k >= settle) {
      t.push_back(static_cast<double>(k + 1) * T);
      y.push_back(reading);
    }
  }
  return triangle_peak_residual(t, y, 6e-3);
}

ValvePredictiveDesign design_valve_predictive(const ValvePredictiveValve& valve, double period_s, double dither_frequency_hz,
                                              const ValvePredictiveGrid& grid) {
  if (grid.preview_samples.empty() || grid.rate_weights_m2_per_a2.empty() || grid.dither_fractions.empty() ||
      grid.disturbance_walks_a.empty() || grid.headroom_fractions.empty() || grid.seeds.empty())
    throw std::invalid_argument("design_valve_predictive: every list of the grid needs at least one value");
  ValvePredictiveDesign d;
  d.peak_m = INFINITY;
  for (int preview : grid.preview_samples) {
    for (double rho : grid.rate_weights_m2_per_a2) {
      for (double dither : grid.dither_fractions) {
        for (double walk : grid.disturbance_walks_a) {
          for (double headroom : grid.headroom_fractions) {
            ValvePredictiveSettings s;
            s.preview_samples = preview;
            s.rate_weight_m2_per_a2 = rho;
            s.dither_fraction = dither;
            s.disturbance_walk_a = walk;
            s.headroom_fraction = headroom;
            ValvePredictiveParams law = valve_predictive_params(valve, period_s, dither_frequency_hz, s);
            double sum = 0.0;
            for (std::uint64_t seed : grid.seeds) sum += predictive_triangle_peak(valve, law, seed);
            const double peak = sum / static_cast<double>(grid.seeds.size());
            d.candidates.push_back({s, peak});
            if (peak < d.peak_m) {
              d.peak_m = peak;
              d.settings = s;
              d.law = std::move(law);
            }
          }
        }
      }
    }
  }
  return d;
}

}  // namespace hsa::control
