// The LVDT on the proportional valve's plunger, Canuto et al. (2014), eq 7, and the
// board's anti-aliasing stage between it and the 10 kHz valve loop (section 2.3, Fig. 3):
//
//   tau_s dx_s/dt = -x_s + K_s (1 + dK_s) x + e_s,      tau_s = 1 / (2 pi 500 Hz)
//   y_s = x_s + b_s,   V_m = sat(y_s, V_max)
//   e_s = sum_k E_sk sin(2 pi k f_s t + phi_sk) + eta_s
//   y_x = AA(V_m sampled at 200 kHz), read by the loop every step
//
// The model works in metres: every voltage of eq 7 is divided by the nominal gain K_s, so the
// output is a position, a scale-factor error dK_s shows as a relative error and the bias b_s and
// the ripple amplitudes E_sk are in metres. K_s only matters for the saturation, which the ADC
// imposes in volts.
//
// The sensor. The filter is linear, so the position and the white noise eta_s go through its
// exact zero-order-hold discretization, while the ripple is added as the filter's steady-state
// response to each harmonic (amplitude E_sk / sqrt(1 + (2 pi k f_s tau_s)^2)). Integrating a 5 kHz
// sine with a coarse step instead would alias inside the integrator and make the ripple depend on
// the step. eta_s is drawn once per step and held over it.
//
// The anti-aliasing stage. Section 2.3: the sensor error was "retrieved upstairs (wide-band noise)
// and downstairs (digitally filtered noise) a digital anti-aliasing filter. The low-frequency
// content is respected until 1 kHz, just above the sensor BW", with "a 200 kHz sampling"; section
// 3.2: "Suitable (analogue/digital) filters have been designed to avoid aliasing as shown in
// Figure 3 for the position sensor errors"; and eq 14 feeds the predictor "the anti-aliased
// measurement y_x". So V_m is sampled at adc_rate_hz (each step is cut into the whole number of
// ADC samples that reaches that rate: 20 at the rig's 100 us), every sample goes through a digital
// Butterworth low-pass (anti_aliasing_order, cut-off anti_aliasing_hz), and the loop reads the
// filter's output at the end of the step. The filter is a cascade of trapezoidal state-variable
// sections (the bilinear transform of the analogue Butterworth, pre-warped at the cut-off), whose
// steady state equals its input exactly, so a constant or a clipped reading comes out unchanged.
// The paper gives no order or cut-off; the default 4th order at 2 kHz keeps -0.02 dB at 1 kHz and
// 0.2 ms of group delay, and takes 32 dB off the 5 kHz excitation ripple that the loop's 10 kHz
// sampling would otherwise fold onto its Nyquist frequency (and 56 dB off the second harmonic,
// which it would fold onto DC). Order 0 removes the stage: the loop then reads V_m itself, aliasing
// included.
//
// Everything is computed in the constructor; step() neither allocates nor throws.
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
  // 30, so the sensor's output ripple is about 2.0, 0.5 and 0.17 um: the excitation peaks of
  // Fig. 3 upstairs of the anti-aliasing filter.
  std::array<double, 3> ripple_amplitude_m{20e-6, 10e-6, 5e-6};
  std::array<double, 3> ripple_phase_rad{0.0, 0.0, 0.0};
  // eta_s: one-sided root spectral density of the input white noise. With unit DC gain it is also
  // the flat low-frequency floor of the output, the ~0.04 um/sqrt(Hz) of Fig. 3 (section 4.3); the
  // sensor's output RMS is density * sqrt(pi/2 * bandwidth), about 1.1 um, and about 1.03 um after
  // the default anti-aliasing filter.
  double noise_density_m_per_sqrt_hz = 0.04e-6;

  // The anti-aliasing stage (section 2.3): ADC rate, and the digital Butterworth low-pass's
  // cut-off and order (0: no filter; otherwise even, at most 8). The cut-off must stay below a
  // quarter of the ADC rate.
  double adc_rate_hz = 200e3;
  double anti_aliasing_hz = 2000.0;
  int anti_aliasing_order = 4;

  std::uint64_t seed = 1;  // seeds eta_s

  friend bool operator==(const LvdtParameters&, const LvdtParameters&) = default;
};

class LvdtSensor {
 public:
  // step_s: the fixed step of every step() call, > 0. Throws std::invalid_argument on a step or
  // parameter outside its range.
  LvdtSensor(const LvdtParameters& parameters, double step_s);

  // Restarts as freshly constructed (random sequence and excitation phase included), with the
  // sensor filter settled on true_position_m and the anti-aliasing filter on the sensor's mean
  // output. The constructor does reset(0).
  void reset(double true_position_m);

  // Advances by step_s, the true position being held over the step, then samples the output.
  void step(double true_position_m);

  // The anti-aliased measurement y_x, what the loop reads: m, and V.
  [[nodiscard]] double value() const { return value_m_; }
  [[nodiscard]] double voltage() const { return voltage_; }
  // The sensor's output V_m at the end of the step, upstairs of the anti-aliasing filter, in m;
  // and whether it is clipped at V_max.
  [[nodiscard]] double sensor_value() const { return sensor_value_m_; }
  [[nodiscard]] bool saturated() const { return saturated_; }

  // RMS of the white noise in value() (through the sensor and anti-aliasing filters) and in
  // sensor_value() (through the sensor filter only), from the parameters.
  [[nodiscard]] double noise_rms() const { return noise_rms_; }
  [[nodiscard]] double sensor_noise_rms() const;
  // Amplitude of ripple harmonic k + 1 (k < 3) at the sensor's output, and in value() (before the
  // loop's sampling folds it).
  [[nodiscard]] double ripple_amplitude(std::size_t k) const { return ripple_out_amplitude_[k]; }
  [[nodiscard]] double measured_ripple_amplitude(std::size_t k) const { return ripple_measured_amplitude_[k]; }
  // Gain of the digital anti-aliasing filter at frequency_hz (below half the ADC rate): 1 without
  // it.
  [[nodiscard]] double anti_aliasing_gain(double frequency_hz) const;

  [[nodiscard]] double time_constant_s() const { return tau_s_; }
  [[nodiscard]] double step_s() const { return step_s_; }
  [[nodiscard]] int adc_samples_per_step() const { return adc_samples_; }
  [[nodiscard]] const LvdtParameters& parameters() const { return p_; }

 private:
  static constexpr std::size_t kHarmonics = 3;
  static constexpr std::size_t kMaxSections = 4;

  // One ADC sample of V_m with the sensor state and ripple phasors as they are, in V: unclipped
  // (step() computes it inline, clipped), and clipped with sensor_value() and saturated() set
  // from it.
  [[nodiscard]] double sensor_voltage(const std::array<double, kHarmonics>& ripple_sin) const;
  double record_sensor_sample(const std::array<double, kHarmonics>& ripple_sin);
  void set_output(double filtered_v);

  LvdtParameters p_;
  double step_s_;
  double tau_s_;
  int adc_samples_ = 1;  // ADC samples per step
  double filter_gain_;   // 1 - exp(-adc period / tau_s)
  double cycles_per_step_;
  std::array<double, kHarmonics> ripple_out_amplitude_{};
  std::array<double, kHarmonics> ripple_out_phase_{};
  std::array<double, kHarmonics> ripple_measured_amplitude_{};
  std::array<double, kHarmonics> rotate_cos_{};  // ripple phasor rotation per ADC sample
  std::array<double, kHarmonics> rotate_sin_{};
  double noise_rms_ = 0.0;

  // Trapezoidal state-variable sections (Simper): a1 = 1 / (1 + g (g + k)), a2 = g a1, a3 = g a2
  // with g = tan(pi f_c / f_adc) and k = 2 zeta of the section.
  std::size_t sections_ = 0;
  std::array<double, kMaxSections> a1_{};
  std::array<double, kMaxSections> a2_{};
  std::array<double, kMaxSections> a3_{};
  std::array<double, kMaxSections> ic1_{};    // the sections' states, V: ic1,
  std::array<double, kMaxSections> e2_{};     // ic2 - input_
  std::array<double, kMaxSections> input_{};  // and the sections' last inputs

  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_;

  double filter_ = 0.0;             // x_s, m
  double excitation_cycles_ = 0.0;  // f_s t, wrapped to [0, 1)
  double value_m_ = 0.0;
  double voltage_ = 0.0;
  double sensor_value_m_ = 0.0;
  bool saturated_ = false;
};

}  // namespace hsa::sim
