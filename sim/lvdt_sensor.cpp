#include "sim/lvdt_sensor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::sim {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Damping ratio of 2nd-order section s of an order-n Butterworth low-pass.
double butterworth_zeta(std::size_t s, int order) {
  return std::sin(std::numbers::pi * (2.0 * static_cast<double>(s) + 1.0) / (2.0 * order));
}

}  // namespace

LvdtSensor::LvdtSensor(const LvdtParameters& parameters, double step_s)
    : p_(parameters), step_s_(step_s) {
  if (!(step_s > 0.0)) {
    throw std::invalid_argument("LvdtSensor: step_s must be > 0");
  }
  if (!(p_.bandwidth_hz > 0.0) || !(p_.gain_v_per_m > 0.0) || !(p_.output_limit_v > 0.0) ||
      !(p_.excitation_hz >= 0.0) || !(p_.noise_density_m_per_sqrt_hz >= 0.0)) {
    throw std::invalid_argument("LvdtSensor: parameter out of range");
  }
  const bool filtered = p_.anti_aliasing_order != 0;
  if (p_.anti_aliasing_order < 0 || p_.anti_aliasing_order % 2 != 0 ||
      p_.anti_aliasing_order > static_cast<int>(2 * kMaxSections) ||
      (filtered && (!(p_.adc_rate_hz > 0.0) || !(p_.anti_aliasing_hz > 0.0)))) {
    throw std::invalid_argument("LvdtSensor: anti-aliasing filter out of range");
  }

  tau_s_ = 1.0 / (kTwoPi * p_.bandwidth_hz);
  if (filtered) {
    // The whole number of ADC samples per step reaching adc_rate_hz (20 for 100 us at 200 kHz;
    // the tolerance keeps a product like 1e-4 * 2e5 from rounding up to 21).
    const double samples = std::ceil(step_s_ * p_.adc_rate_hz - 1e-9);
    if (!(samples < 1e6)) throw std::invalid_argument("LvdtSensor: too many ADC samples per step");
    adc_samples_ = std::max(1, static_cast<int>(samples));
  }
  const double adc_period = step_s_ / adc_samples_;
  if (filtered && !(p_.anti_aliasing_hz < 0.25 / adc_period)) {
    throw std::invalid_argument("LvdtSensor: anti-aliasing cut-off must be below a quarter of the ADC rate");
  }
  filter_gain_ = -std::expm1(-adc_period / tau_s_);
  cycles_per_step_ = p_.excitation_hz * step_s_;

  if (filtered) {
    sections_ = static_cast<std::size_t>(p_.anti_aliasing_order / 2);
    const double g = std::tan(std::numbers::pi * p_.anti_aliasing_hz * adc_period);
    for (std::size_t s = 0; s < sections_; ++s) {
      const double k = 2.0 * butterworth_zeta(s, p_.anti_aliasing_order);
      a1_[s] = 1.0 / (1.0 + g * (g + k));
      a2_[s] = g * a1_[s];
      a3_[s] = g * a2_[s];
    }
  }

  for (std::size_t k = 0; k < kHarmonics; ++k) {
    const double harmonic_hz = static_cast<double>(k + 1) * p_.excitation_hz;
    const double omega_tau = kTwoPi * harmonic_hz * tau_s_;
    ripple_out_amplitude_[k] = p_.ripple_amplitude_m[k] / std::hypot(1.0, omega_tau);
    ripple_out_phase_[k] = p_.ripple_phase_rad[k] - std::atan(omega_tau);
    ripple_measured_amplitude_[k] = ripple_out_amplitude_[k] * anti_aliasing_gain(harmonic_hz);
    rotate_cos_[k] = std::cos(kTwoPi * harmonic_hz * adc_period);
    rotate_sin_[k] = std::sin(kTwoPi * harmonic_hz * adc_period);
  }

  // Sampled white noise of one-sided density S has variance S / (2 step): its two-sided density
  // S / 2 spread over the band +-1 / (2 step).
  const double sigma = p_.noise_density_m_per_sqrt_hz / std::sqrt(2.0 * step_s_);
  noise_ = std::normal_distribution<double>(0.0, sigma);

  // Noise power through the sensor filter and the (analogue prototype of the) anti-aliasing
  // filter: S * integral of |H_s|^2 |H_aa|^2 df over f >= 0. With f = phi_s tan(theta), |H_s|^2 df
  // becomes phi_s d(theta) on [0, pi/2), which Simpson's rule integrates well.
  if (filtered) {
    constexpr int kIntervals = 4096;  // even
    const double h = 0.5 * std::numbers::pi / kIntervals;
    double sum = 0.0;
    for (int i = 0; i <= kIntervals; ++i) {
      double integrand = 0.0;  // at theta = pi/2 the anti-aliasing filter has removed everything
      if (i < kIntervals) {
        const double f = p_.bandwidth_hz * std::tan(i * h);
        integrand = p_.bandwidth_hz / (1.0 + std::pow(f / p_.anti_aliasing_hz, 2.0 * p_.anti_aliasing_order));
      }
      sum += (i == 0 || i == kIntervals ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0)) * integrand;
    }
    noise_rms_ = p_.noise_density_m_per_sqrt_hz * std::sqrt(sum * h / 3.0);
  } else {
    noise_rms_ = sensor_noise_rms();
  }
  reset(0.0);
}

double LvdtSensor::sensor_noise_rms() const {
  // Equivalent noise bandwidth of a first-order low-pass: pi/2 times its -3 dB bandwidth.
  return p_.noise_density_m_per_sqrt_hz * std::sqrt(0.5 * std::numbers::pi * p_.bandwidth_hz);
}

double LvdtSensor::anti_aliasing_gain(double frequency_hz) const {
  if (sections_ == 0) return 1.0;
  // The bilinear transform maps f onto the analogue frequency tan(pi f T) / (pi T), and the
  // pre-warped Butterworth has |H| = 1 / sqrt(1 + (w / w_c)^(2n)) there.
  const double adc_period = step_s_ / adc_samples_;
  const double ratio = std::tan(std::numbers::pi * frequency_hz * adc_period) /
                       std::tan(std::numbers::pi * p_.anti_aliasing_hz * adc_period);
  return 1.0 / std::sqrt(1.0 + std::pow(std::abs(ratio), 2.0 * p_.anti_aliasing_order));
}

void LvdtSensor::reset(double true_position_m) {
  filter_ = (1.0 + p_.scale_factor_error) * true_position_m;
  excitation_cycles_ = 0.0;
  rng_.seed(p_.seed);
  noise_.reset();

  std::array<double, kHarmonics> ripple_sin{};
  for (std::size_t k = 0; k < kHarmonics; ++k) ripple_sin[k] = std::sin(ripple_out_phase_[k]);
  const double v = record_sensor_sample(ripple_sin);
  // The anti-aliasing filter settles on the sensor's mean output (without the ripple); its
  // sections' steady state is ic1 = 0, ic2 = input.
  const double mean_v = std::clamp(p_.gain_v_per_m * (filter_ + p_.bias_m), -p_.output_limit_v, p_.output_limit_v);
  for (std::size_t s = 0; s < sections_; ++s) {
    ic1_[s] = 0.0;
    e2_[s] = 0.0;
    input_[s] = mean_v;
  }
  set_output(sections_ == 0 ? v : mean_v);
}

void LvdtSensor::step(double true_position_m) {
  const double input = (1.0 + p_.scale_factor_error) * true_position_m + noise_(rng_);

  // Ripple phasors at the start of the step; each ADC sample rotates them by its period. The
  // excitation phase is wrapped to keep the arguments small however long the run; f_s step is
  // exact for the default 5 kHz and 1e-4 s, and otherwise drifts by one rounding error per step.
  std::array<double, kHarmonics> ripple_sin{};
  std::array<double, kHarmonics> ripple_cos{};
  for (std::size_t k = 0; k < kHarmonics; ++k) {
    const double phase = kTwoPi * static_cast<double>(k + 1) * excitation_cycles_ + ripple_out_phase_[k];
    ripple_sin[k] = std::sin(phase);
    ripple_cos[k] = std::cos(phase);
  }

  double v = 0.0;
  for (int n = 0; n < adc_samples_; ++n) {
    filter_ += filter_gain_ * (input - filter_);
    for (std::size_t k = 0; k < kHarmonics; ++k) {
      const double s = ripple_sin[k] * rotate_cos_[k] + ripple_cos[k] * rotate_sin_[k];
      ripple_cos[k] = ripple_cos[k] * rotate_cos_[k] - ripple_sin[k] * rotate_sin_[k];
      ripple_sin[k] = s;
    }
    double ripple = 0.0;
    for (std::size_t k = 0; k < kHarmonics; ++k) ripple += ripple_out_amplitude_[k] * ripple_sin[k];
    v = std::clamp(p_.gain_v_per_m * (filter_ + ripple + p_.bias_m), -p_.output_limit_v, p_.output_limit_v);
    // The anti-aliasing sections in cascade, one trapezoidal step each. The second state is kept
    // relative to the section's input (e2 = ic2 - input), so that under a constant input it decays
    // to zero and the output becomes the input exactly, instead of stalling a few rounding errors
    // away from it.
    for (std::size_t s = 0; s < sections_; ++s) {
      e2_[s] += input_[s] - v;
      input_[s] = v;
      const double v1 = a1_[s] * ic1_[s] - a2_[s] * e2_[s];
      const double d2 = e2_[s] + a2_[s] * ic1_[s] - a3_[s] * e2_[s];  // section output - input
      ic1_[s] = 2.0 * v1 - ic1_[s];
      e2_[s] = 2.0 * d2 - e2_[s];
      v += d2;
    }
  }

  // What the step leaves visible is the last ADC sample's, so its clipping and value are
  // recorded once here rather than at each of the step's samples.
  record_sensor_sample(ripple_sin);
  excitation_cycles_ += cycles_per_step_;
  excitation_cycles_ -= std::floor(excitation_cycles_);
  set_output(v);
}

double LvdtSensor::sensor_voltage(const std::array<double, kHarmonics>& ripple_sin) const {
  double ripple = 0.0;
  for (std::size_t k = 0; k < kHarmonics; ++k) ripple += ripple_out_amplitude_[k] * ripple_sin[k];
  return p_.gain_v_per_m * (filter_ + ripple + p_.bias_m);
}

double LvdtSensor::record_sensor_sample(const std::array<double, kHarmonics>& ripple_sin) {
  const double v = sensor_voltage(ripple_sin);
  saturated_ = std::abs(v) > p_.output_limit_v;
  const double clipped = std::clamp(v, -p_.output_limit_v, p_.output_limit_v);
  sensor_value_m_ = clipped / p_.gain_v_per_m;
  return clipped;
}

void LvdtSensor::set_output(double filtered_v) {
  voltage_ = filtered_v;
  value_m_ = voltage_ / p_.gain_v_per_m;
}

}  // namespace hsa::sim
