#include "control/identification/valve_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hsa::control::identification {

ValveModelState rest_state(const ValveModel& model, double position_m) {
  ValveModelState s;
  s.position_m = std::clamp(position_m, model.rest_position_m, model.stroke_max_m);
  s.force_current_a = model.gain_m_per_a > 0.0 ? (s.position_m - model.rest_position_m) / model.gain_m_per_a : 0.0;
  s.play_a = s.force_current_a;
  s.sensor_m = s.position_m;
  return s;
}

std::vector<double> simulate_valve(const ValveModel& model, const std::vector<double>& current_a, double period_s,
                                   const ValveModelState& start, std::size_t first, std::size_t last,
                                   std::vector<ValveModelState>* states) {
  constexpr double kMaxSubstep = 25e-6;
  const int substeps = std::max(1, static_cast<int>(std::ceil(period_s / kMaxSubstep - 1e-9)));
  const double h = period_s / substeps;
  const long delay = std::max(0L, std::lround(model.delay_s / h));
  const double omega0 = 2.0 * std::numbers::pi * model.natural_frequency_hz;
  const double w2 = omega0 * omega0;
  const double damping = 2.0 * model.damping_ratio * omega0;
  const double friction = w2 * model.friction_band_m;
  const double lag = -std::expm1(-h / std::max(model.magnetic_lag_s, 1e-9));
  const double sensor = -std::expm1(-period_s * 2.0 * std::numbers::pi * model.sensor_bandwidth_hz);
  const double lo = model.rest_position_m;
  const double hi = model.stroke_max_m;

  ValveModelState s = start;
  last = std::min(last, current_a.size());
  first = std::min(first, last);
  std::vector<double> y(last - first);
  if (states != nullptr) states->resize(last - first);
  for (std::size_t k = first; k < last; ++k) {
    if (states != nullptr) (*states)[k - first] = s;
    for (int i = 0; i < substeps; ++i) {
      // The current δ before this substep's start, held over its sample period.
      const long substep = static_cast<long>(k) * substeps + i - delay;
      const long source = substep >= 0 ? substep / substeps : -1;
      const double current = current_a[static_cast<std::size_t>(std::max(0L, source))];
      s.play_a = std::clamp(s.play_a, current - model.width_a, current);
      s.force_current_a += lag * (s.play_a - s.force_current_a);
      double& x = s.position_m;
      double& v = s.velocity_m_s;
      const double drive = w2 * (model.gain_m_per_a * s.force_current_a - (x - lo));
      if ((x >= hi && drive >= 0.0 && v >= 0.0) || (x <= lo && drive <= 0.0 && v <= 0.0)) {
        v = 0.0;  // pressed against a stop
        continue;
      }
      if (v == 0.0 && std::abs(drive) <= friction) continue;  // stiction holds
      const double direction = v != 0.0 ? std::copysign(1.0, v) : std::copysign(1.0, drive);
      double v_new = (v + h * (drive - friction * direction)) / (1.0 + h * damping);
      if (v_new * v < 0.0 && std::abs(drive) <= friction) v_new = 0.0;
      v = v_new;
      x += h * v;
      if (x > hi) {
        x = hi;
        v = 0.0;
      } else if (x < lo) {
        x = lo;
        v = 0.0;
      }
    }
    s.sensor_m += sensor * (s.position_m - s.sensor_m);
    y[k - first] = s.sensor_m;
  }
  return y;
}

}  // namespace hsa::control::identification
