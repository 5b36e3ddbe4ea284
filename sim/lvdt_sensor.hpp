// The LVDT on the proportional valve's plunger, Canuto et al. (2014, paper 001), eq 7:
//
//   tau_s dx_s/dt = -x_s + K_s (1 + dK_s) x + e_s,      tau_s = 1 / (2 pi 500 Hz)
//   y_s = x_s + b_s,   V_m = sat(y_s, V_max)
//   e_s = sum_k E_sk sin(2 pi k f_s t + phi_sk) + eta_s
//
// The model works in metres: every voltage of eq 7 is divided by the nominal gain K_s, so the
// output is a position, a scale-factor error dK_s shows as a relative error and the bias b_s and
// the ripple amplitudes E_sk are in metres. K_s only matters for the saturation, which the ADC
// imposes in volts.
//
// The filter is linear, so the position and the white noise eta_s go through its exact
// zero-order-hold discretization, while the ripple is added as the filter's steady-state response
// to each harmonic (amplitude E_sk / sqrt(1 + (2 pi k f_s tau_s)^2)). Integrating a 5 kHz sine with
// a 1e-4 s step instead would alias inside the integrator and make the ripple depend on the step.
// The output samples do alias, as the board's ADC does: at a 10 kHz step the fundamental appears
// at the Nyquist frequency and the second harmonic as a constant offset (the "residual aliasing"
// of section 2.3).
//
// Everything is allocated in the constructor; step() neither allocates nor throws.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>

namespace hsa::sim {

struct LvdtParameters {
  double bandwidth_hz = 500.0;          // output filter bandwidth phi_s
  double gain_v_per_m = 3300.0;         // nominal K_s (3.3 V/mm)
  double scale_factor_error = 0.0;      // dK_s, relative
  double bias_m = 0.0;                  // b_s: mounting and electronics offset from hydraulic zero
  double output_limit_v = 10.0;         // V_max, the ADC range: +-3.03 mm at the nominal gain

  double excitation_hz = 5000.0;  // f_s, close to the PWM Nyquist frequency
  // E_sk, as a position error at the filter input. The filter divides them by about 10, 20 and
  // 30, so the output ripple is about 2.0, 0.5 and 0.17 um: the excitation peaks of Fig. 3, a few
  // um together, comfortably inside the +-10 um residual error the valve loop must reach (eq 8).
  std::array<double, 3> ripple_amplitude_m{20e-6, 10e-6, 5e-6};
  std::array<double, 3> ripple_phase_rad{0.0, 0.0, 0.0};
  // eta_s: one-sided root spectral density of the input white noise. With unit DC gain it is also
  // the flat low-frequency floor of the output, the ~0.04 um/sqrt(Hz) of Fig. 3 (section 4.3); the
  // output RMS is density * sqrt(pi/2 * bandwidth), about 1.1 um.
  double noise_density_m_per_sqrt_hz = 0.04e-6;

  std::uint64_t seed = 1;  // seeds eta_s
};

class LvdtSensor {
 public:
  // step_s: the fixed step of every step() call, > 0. Throws std::invalid_argument on a step or
  // parameter outside its range.
  LvdtSensor(const LvdtParameters& parameters, double step_s);

  // Restarts as freshly constructed (random sequence and excitation phase included), with the
  // filter settled on true_position_m. The constructor does reset(0).
  void reset(double true_position_m);

  // Advances by step_s, the true position being held over the step, then samples the output.
  void step(double true_position_m);

  [[nodiscard]] double value() const { return value_m_; }    // measured position, m
  [[nodiscard]] double voltage() const { return voltage_; }  // V_m, V
  [[nodiscard]] bool saturated() const { return saturated_; }

  // RMS of the output white noise, and output amplitude of ripple harmonic k + 1 (k < 3), from the
  // parameters.
  [[nodiscard]] double noise_rms() const;
  [[nodiscard]] double ripple_amplitude(std::size_t k) const {
    return ripple_out_amplitude_[k];
  }

  [[nodiscard]] double time_constant_s() const { return tau_s_; }
  [[nodiscard]] double step_s() const { return step_s_; }
  [[nodiscard]] const LvdtParameters& parameters() const { return p_; }

 private:
  void sample_output();

  static constexpr std::size_t kHarmonics = 3;

  LvdtParameters p_;
  double step_s_;
  double tau_s_;
  double filter_gain_;   // 1 - exp(-step / tau_s)
  double cycles_per_step_;
  std::array<double, kHarmonics> ripple_out_amplitude_{};
  std::array<double, kHarmonics> ripple_out_phase_{};

  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_;

  double filter_ = 0.0;          // x_s, m
  double excitation_cycles_ = 0.0;  // f_s t, wrapped to [0, 1)
  double value_m_ = 0.0;
  double voltage_ = 0.0;
  bool saturated_ = false;
};

}  // namespace hsa::sim
