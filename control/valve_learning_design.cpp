#include "control/valve_learning_design.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::control {

namespace {

using Complex = std::complex<double>;

// The harmonic n of the period as a signed frequency: n ≤ N/2 positive, above it the negative
// frequencies of the DFT.
double harmonic_hz(int n, int period_samples, double period_s) {
  const int signed_n = n <= period_samples / 2 ? n : n - period_samples;
  return signed_n / (period_samples * period_s);
}

// Σ_j c_j·e^{−i·2π·j·n/N}: a centred filter's response at harmonic n.
Complex response(const std::vector<double>& centred, int n, int period_samples) {
  const int m = static_cast<int>(centred.size() / 2);
  Complex sum = 0.0;
  for (int j = -m; j <= m; ++j)
    sum += centred[static_cast<std::size_t>(j + m)] * std::polar(1.0, -2.0 * std::numbers::pi * j * n / period_samples);
  return sum;
}

// G at a signed frequency: G(−f) = conj(G(f)) for a real loop.
Complex loop_at(const IdentifiedValve& v, const ValveLawParams& law, double f) {
  const Complex g = valve_loop_response(v, law, std::abs(f));
  return f < 0.0 ? std::conj(g) : g;
}

}  // namespace

// Chosen on the simulator with hsa-analyze experiment valve (docs/valve-loop.md, "learning"):
// f_Q 100, 150, 200, 300 Hz and k_L 0.2, 0.5. k_L = 0.5 learned the corners' repeating part down
// (32 → 22 µm) but fed back twice the non-repeating spool motion (5 → 9.5 µm rms); 0.2 keeps that
// in check. f_Q = 300 Hz reaches the corner transient's harmonics; M = 100 samples holds both
// filters (Q's kernel is a few samples wide, H's is Q's shifted by the loop's ~17 samples).
ValveLearningSettings valve_learning_settings() {
  return {.filter_hz = 300.0, .gain = 0.2, .half_width = 100, .settle_periods = 10};
}

Complex valve_loop_response(const IdentifiedValve& v, const ValveLawParams& p, double f) {
  const double w = 2.0 * std::numbers::pi * f;
  const Complex s(0.0, w);
  const double w0 = 2.0 * std::numbers::pi * v.natural_frequency_hz;
  const Complex plant = v.gain_m_per_a * std::exp(-s * v.delay_s) /
                        ((1.0 + s * v.magnetic_lag_s) * (1.0 + 2.0 * v.damping_ratio * s / w0 + s * s / (w0 * w0)));
  // At f = 0 the integral dominates both C_r and C_x: their ratio, and G, tend to 1.
  const Complex integral = p.integral_a_per_m_s <= 0.0 ? Complex(0.0) : f > 0.0 ? p.integral_a_per_m_s / s : Complex(1e12);
  const Complex feedforward = p.feedforward_a_per_m + p.reference_velocity_a_per_m_s * s +
                              p.reference_acceleration_a_per_m_s2 * s * s +
                              p.reference_jerk_a_per_m_s3 * s * s * s + p.proportional_a_per_m + integral;
  const Complex feedback =
      p.proportional_a_per_m + integral + p.velocity_a_per_m_s * s + p.acceleration_a_per_m_s2 * s * s;
  const double wr = 2.0 * std::numbers::pi * p.reference_filter_hz;
  const Complex filter = p.reference_filter_hz > 0.0 ? std::pow(wr / (s + wr), 3) : Complex(1.0);
  const Complex tracked = p.track_filtered_reference ? filter : Complex(1.0);
  // Without tracking the filtered reference the feedback acts on r itself and only the model
  // terms see r_f; the learning step always runs on the model-inverse law, which tracks r_f.
  return tracked * plant * feedforward / (1.0 + plant * feedback) * std::exp(-1.5 * s * p.period_s);
}

ValveLearningDesign design_valve_learning(const IdentifiedValve& v, const ValveLawParams& law, int n_samples,
                                          const ValveLearningSettings& st) {
  if (n_samples < 4) throw std::invalid_argument("design_valve_learning: the period must be at least 4 samples");
  if (!(st.filter_hz > 0.0)) throw std::invalid_argument("design_valve_learning: f_Q must be > 0");
  if (!(st.gain > 0.0 && st.gain < 2.0)) throw std::invalid_argument("design_valve_learning: k_L must lie in (0, 2)");
  if (st.half_width < 1) throw std::invalid_argument("design_valve_learning: M must be >= 1");
  const double t = law.period_s;
  ValveLearningDesign d;
  d.period_samples = n_samples;
  const int m = std::min(st.half_width, (n_samples - 1) / 2);
  // Q and H at every harmonic of the period, then their inverse DFTs at |j| ≤ M.
  std::vector<Complex> q(static_cast<std::size_t>(n_samples)), h(q.size());
  for (int n = 0; n < n_samples; ++n) {
    const double f = harmonic_hz(n, n_samples, t);
    const double qf = std::pow(2.0, -0.5 * (f / st.filter_hz) * (f / st.filter_hz));
    q[static_cast<std::size_t>(n)] = qf;
    h[static_cast<std::size_t>(n)] = st.gain * qf / loop_at(v, law, f);
  }
  if (n_samples % 2 == 0) {  // the Nyquist bin of a real filter is real
    q[static_cast<std::size_t>(n_samples / 2)] = q[static_cast<std::size_t>(n_samples / 2)].real();
    h[static_cast<std::size_t>(n_samples / 2)] = h[static_cast<std::size_t>(n_samples / 2)].real();
  }
  d.filter.assign(static_cast<std::size_t>(2 * m + 1), 0.0);
  d.kernel.assign(d.filter.size(), 0.0);
  for (int j = -m; j <= m; ++j) {
    Complex qj = 0.0, hj = 0.0;
    for (int n = 0; n < n_samples; ++n) {
      const Complex turn = std::polar(1.0, 2.0 * std::numbers::pi * j * n / n_samples);
      qj += q[static_cast<std::size_t>(n)] * turn;
      hj += h[static_cast<std::size_t>(n)] * turn;
    }
    d.filter[static_cast<std::size_t>(j + m)] = qj.real() / n_samples;
    d.kernel[static_cast<std::size_t>(j + m)] = hj.real() / n_samples;
  }
  const double f1 = 1.0 / (n_samples * t);
  d.delay_samples = std::clamp(static_cast<int>(std::lround(-std::arg(loop_at(v, law, f1)) / (2.0 * std::numbers::pi * f1 * t))),
                               0, n_samples - 1);
  const std::vector<double> rho = valve_learning_convergence(v, law, d);
  d.convergence = *std::max_element(rho.begin(), rho.end());
  return d;
}

std::vector<double> valve_learning_convergence(const IdentifiedValve& v, const ValveLawParams& law,
                                               const ValveLearningDesign& d) {
  std::vector<double> rho;
  for (int n = 0; n <= d.period_samples / 2; ++n) {
    const double f = harmonic_hz(n, d.period_samples, law.period_s);
    rho.push_back(std::abs(response(d.filter, n, d.period_samples) -
                           response(d.kernel, n, d.period_samples) * loop_at(v, law, f)));
  }
  return rho;
}

}  // namespace hsa::control
