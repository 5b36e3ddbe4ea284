#include "control/valve_feedback_design.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "control/command_delay_line.hpp"
#include "control/valve_model_predictor.hpp"
#include "control/valve_triangle_residual.hpp"

namespace hsa::control {

namespace {

// The identified valve as a plant: eqs 1–3 and 6 with the identified parameters only.
class IdentifiedValvePlant {
 public:
  IdentifiedValvePlant(const IdentifiedValve& v, double period_s, double current_a)
      : v_(v),
        h_(period_s / kSubsteps),
        w0_(2.0 * std::numbers::pi * v.natural_frequency_hz),
        delay_(static_cast<int>(std::lround(v.delay_s / period_s))) {
    delay_.fill(current_a);
    play_ = force_ = current_a - 0.5 * v.width_a;
    x_ = v.rest_position_m + v.gain_m_per_a * force_;
  }

  [[nodiscard]] double position() const { return x_; }

  void step(double current_a) {
    const double entering = delay_.push(current_a);
    // The play (eq 6): rising, it sits w below the current; falling, at it.
    if (entering > play_ + v_.width_a) {
      play_ = entering - v_.width_a;
    } else if (entering < play_) {
      play_ = entering;
    }
    for (int k = 0; k < kSubsteps; ++k) {
      force_ += h_ / v_.magnetic_lag_s * (play_ - force_);
      const double a = w0_ * w0_ * (v_.rest_position_m + v_.gain_m_per_a * force_ - x_) - 2.0 * v_.damping_ratio * w0_ * vel_;
      vel_ += h_ * a;
      x_ += h_ * vel_;
    }
  }

 private:
  static constexpr int kSubsteps = 4;
  IdentifiedValve v_;
  double h_, w0_;
  CommandDelayLine delay_;
  double play_ = 0.0, force_ = 0.0, x_ = 0.0, vel_ = 0.0;
};

// The 70 % triangle at 10 Hz on the design model: eq 9's peak residual against the best delay.
double triangle_peak(const IdentifiedValve& valve, const ValveLawParams& law, const ValveFeedbackDesignSettings& s) {
  constexpr double kAmplitudeM = kDesignTriangleAmplitudeM;
  constexpr double kFrequencyHz = kDesignTriangleFrequencyHz;
  const double T = law.period_s;
  ValveLaw l(law);
  ValveModelPredictor predictor(law.model_predictor, T);
  IdentifiedValvePlant plant(valve, T, law.bias_current_a);
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0.0, s.lvdt_noise_m);
  predictor.reset(plant.position());
  const long period = std::lround(1.0 / (kFrequencyHz * T));
  const long settle = 2 * period, n = settle + 4 * period;
  std::vector<double> t, y;
  for (long k = 0; k < n; ++k) {
    const double reading = plant.position() + (s.lvdt_noise_m > 0.0 ? noise(rng) : 0.0);
    const double current = l.update(kAmplitudeM * unit_triangle(kFrequencyHz, static_cast<double>(k) * T), predictor.update(reading));
    predictor.commanded(current);
    plant.step(current);
    if (k >= settle) {
      t.push_back(static_cast<double>(k + 1) * T);
      y.push_back(plant.position() + (s.lvdt_noise_m > 0.0 ? noise(rng) : 0.0));
    }
  }
  return triangle_peak_residual(t, y, 4e-3);
}

}  // namespace

ValveLawParams with_feedback_factors(ValveLawParams law, double velocity_factor, double acceleration_factor) {
  law.reference_velocity_a_per_m_s += (velocity_factor - 1.0) * law.velocity_a_per_m_s;
  law.velocity_a_per_m_s *= velocity_factor;
  law.reference_acceleration_a_per_m_s2 += (acceleration_factor - 1.0) * law.acceleration_a_per_m_s2;
  law.acceleration_a_per_m_s2 *= acceleration_factor;
  return law;
}

ValveFeedbackDesign design_valve_feedback(const IdentifiedValve& valve, const ValveLawParams& law,
                                          const ValveFeedbackDesignSettings& settings) {
  const auto positive = [](const std::vector<double>& f) {
    return !f.empty() && std::all_of(f.begin(), f.end(), [](double x) { return x > 0.0 && std::isfinite(x); });
  };
  if (!positive(settings.velocity_factors) || !positive(settings.acceleration_factors))
    throw std::invalid_argument("design_valve_feedback: the factor lists must be non-empty and positive");
  if (!(settings.lvdt_noise_m >= 0.0) || !std::isfinite(settings.lvdt_noise_m))
    throw std::invalid_argument("design_valve_feedback: the LVDT noise must be a finite rms >= 0");
  if (!law.model_predictor.enabled)
    throw std::invalid_argument("design_valve_feedback: the law must run behind the model predictor");
  ValveFeedbackDesign d;
  d.peak_m = INFINITY;
  d.preset_peak_m = triangle_peak(valve, law, settings);
  for (double kv : settings.velocity_factors) {
    for (double ka : settings.acceleration_factors) {
      const double peak = triangle_peak(valve, with_feedback_factors(law, kv, ka), settings);
      if (peak < d.peak_m) d = {.velocity_factor = kv, .acceleration_factor = ka, .peak_m = peak, .preset_peak_m = d.preset_peak_m};
    }
  }
  return d;
}

}  // namespace hsa::control
