#include "sim/lvdt_sensor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hsa::sim {

LvdtSensor::LvdtSensor(const LvdtParameters& parameters, double step_s)
    : p_(parameters), step_s_(step_s) {
  if (!(step_s > 0.0)) {
    throw std::invalid_argument("LvdtSensor: step_s must be > 0");
  }
  if (!(p_.bandwidth_hz > 0.0) || !(p_.gain_v_per_m > 0.0) || !(p_.output_limit_v > 0.0) ||
      p_.excitation_hz < 0.0 || p_.noise_density_m_per_sqrt_hz < 0.0) {
    throw std::invalid_argument("LvdtSensor: parameter out of range");
  }

  constexpr double two_pi = 2.0 * std::numbers::pi;
  tau_s_ = 1.0 / (two_pi * p_.bandwidth_hz);
  filter_gain_ = -std::expm1(-step_s_ / tau_s_);
  cycles_per_step_ = p_.excitation_hz * step_s_;
  for (std::size_t k = 0; k < kHarmonics; ++k) {
    const double omega_tau = two_pi * static_cast<double>(k + 1) * p_.excitation_hz * tau_s_;
    ripple_out_amplitude_[k] = p_.ripple_amplitude_m[k] / std::hypot(1.0, omega_tau);
    ripple_out_phase_[k] = p_.ripple_phase_rad[k] - std::atan(omega_tau);
  }

  // Sampled white noise of one-sided density S has variance S / (2 step): its two-sided density
  // S / 2 spread over the band +-1 / (2 step).
  const double sigma = p_.noise_density_m_per_sqrt_hz / std::sqrt(2.0 * step_s_);
  noise_ = std::normal_distribution<double>(0.0, sigma);
  reset(0.0);
}

double LvdtSensor::noise_rms() const {
  // Equivalent noise bandwidth of a first-order low-pass: pi/2 times its -3 dB bandwidth.
  return p_.noise_density_m_per_sqrt_hz * std::sqrt(0.5 * std::numbers::pi * p_.bandwidth_hz);
}

void LvdtSensor::reset(double true_position_m) {
  filter_ = (1.0 + p_.scale_factor_error) * true_position_m;
  excitation_cycles_ = 0.0;
  rng_.seed(p_.seed);
  noise_.reset();
  sample_output();
}

void LvdtSensor::step(double true_position_m) {
  const double input = (1.0 + p_.scale_factor_error) * true_position_m + noise_(rng_);
  filter_ += filter_gain_ * (input - filter_);

  // Wrapping keeps the sine arguments small however long the run; f_s step is exact for the
  // default 5 kHz and 1e-4 s, and otherwise drifts by one rounding error per step at most.
  excitation_cycles_ += cycles_per_step_;
  excitation_cycles_ -= std::floor(excitation_cycles_);
  sample_output();
}

void LvdtSensor::sample_output() {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double ripple = 0.0;
  for (std::size_t k = 0; k < kHarmonics; ++k) {
    const double phase = two_pi * static_cast<double>(k + 1) * excitation_cycles_;
    ripple += ripple_out_amplitude_[k] * std::sin(phase + ripple_out_phase_[k]);
  }
  const double y = filter_ + ripple + p_.bias_m;
  const double v = p_.gain_v_per_m * y;
  saturated_ = std::abs(v) > p_.output_limit_v;
  voltage_ = std::clamp(v, -p_.output_limit_v, p_.output_limit_v);
  value_m_ = voltage_ / p_.gain_v_per_m;
}

}  // namespace hsa::sim
