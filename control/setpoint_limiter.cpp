#include "control/setpoint_limiter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::control {
namespace {

double sign(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }

// How close counts as on the target: a few hundred ulps of a position of a metre, so that
// rounding, not the filter, is all it absorbs.
constexpr double kLandingM = 1e-14;

}  // namespace

SetpointLimiter::SetpointLimiter(const SetpointLimits& limits) : limits_(limits) {
  if (!(limits.speed_m_s > 0.0) || !std::isfinite(limits.speed_m_s)) {
    throw std::invalid_argument("SetpointLimiter: speed bound must be > 0 and finite");
  }
  if (!(limits.accel_m_s2 > 0.0) || !std::isfinite(limits.accel_m_s2)) {
    throw std::invalid_argument("SetpointLimiter: acceleration bound must be > 0 and finite");
  }
  if (!std::isfinite(limits.low_m) || !std::isfinite(limits.high_m) || !(limits.low_m < limits.high_m)) {
    throw std::invalid_argument("SetpointLimiter: position bounds must be finite with low < high");
  }
}

void SetpointLimiter::reset(double position_m, double velocity_m_s) noexcept {
  x_ = std::isfinite(position_m) ? std::clamp(position_m, limits_.low_m, limits_.high_m) : limits_.low_m;
  v_ = std::isfinite(velocity_m_s) ? std::clamp(velocity_m_s, -limits_.speed_m_s, limits_.speed_m_s) : 0.0;
  a_ = 0.0;
  lag_m_ = 0.0;
}

bool SetpointLimiter::step(double target_m, double target_velocity_m_s, double period_s) noexcept {
  if (!std::isfinite(target_m) || !std::isfinite(target_velocity_m_s) || !std::isfinite(period_s) ||
      !(period_s > 0.0)) {
    return false;
  }
  const double T = period_s;
  const double U = limits_.accel_m_s2;
  const double V = limits_.speed_m_s;

  // The goal: the target inside the bounds, moving at most at V; at rest where it is clamped.
  double r = std::clamp(target_m, limits_.low_m, limits_.high_m);
  double r_dot = r == target_m ? std::clamp(target_velocity_m_s, -V, V) : 0.0;
  if ((r == limits_.high_m && r_dot > 0.0) || (r == limits_.low_m && r_dot < 0.0)) r_dot = 0.0;
  // Where the output stops if it brakes after one more step at its speed, with a step's margin
  // for braking in whole steps: past a bound, aim at that bound at rest. (A static target inside
  // the bounds needs no such care: the filter never passes it.)
  const double stop_m = x_ + sign(v_) * (2.0 * std::abs(v_) * T + v_ * v_ / (2.0 * U));
  if (r_dot != 0.0 && v_ > 0.0 && stop_m >= limits_.high_m) {
    r = limits_.high_m;
    r_dot = 0.0;
  } else if (r_dot != 0.0 && v_ < 0.0 && stop_m <= limits_.low_m) {
    r = limits_.low_m;
    r_dot = 0.0;
  }

  // The state is the output's at the start of the step, the target is where the output must be
  // at its end: compared at the same instant, the target was a step's travel behind.
  const double e = (x_ - (r - r_dot * T)) / U;
  const double e_dot = (v_ - r_dot) / U;
  const double z = (e / T + e_dot / 2.0) / T;
  const double z_dot = e_dot / T;
  const double m = std::floor((1.0 + std::sqrt(1.0 + 8.0 * std::abs(z))) / 2.0);  // ≥ 1
  const double sigma = z_dot + z / m + (m - 1.0) / 2.0 * sign(z);
  // The speed bound: accelerate no further than V (the filter's last factor, as a clamp, so that
  // it cruises at V rather than within a step's acceleration of it).
  double v_next = std::clamp(v_ - T * U * std::clamp(sigma, -1.0, 1.0), -V, V);
  double x_next = x_ + T * (v_ + v_next) / 2.0;
  // Landed to the rounding of the arithmetic: on the target, at its speed, exactly (a step of at
  // most kLanding/T in speed, far below the bounds' slack), so a static target is held bit for bit.
  if (std::abs(x_next - r) <= kLandingM && std::abs(v_next - r_dot) <= kLandingM / T) {
    x_next = r;
    v_next = r_dot;
  }
  x_ = std::clamp(x_next, limits_.low_m, limits_.high_m);  // the bounds, to the last bit
  a_ = (v_next - v_) / T;
  v_ = v_next;
  lag_m_ = std::clamp(target_m, limits_.low_m, limits_.high_m) - x_;  // the target's, not the bound's
  return true;
}

}  // namespace hsa::control
