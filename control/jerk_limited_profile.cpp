#include "control/jerk_limited_profile.hpp"

#include <algorithm>
#include <cmath>

namespace hsa::control {

namespace {

// a²/j: the speed gained by a jerk ramp up to a and back down; 0 for an infinite jerk.
double ramp_speed(double accel, double jerk) { return accel * accel / jerk; }

// The time of an acceleration phase from rest to `peak` (header: T_a), and its peak acceleration.
struct Phase {
  double peak_accel = 0.0;
  double jerk_time = 0.0;
  double duration = 0.0;
};

Phase phase_to(double peak, double accel, double jerk) {
  if (peak <= 0.0) return {};
  if (peak >= ramp_speed(accel, jerk)) {
    const double tj = accel / jerk;  // 0 for an infinite jerk
    return {accel, tj, peak / accel + tj};
  }
  const double ap = std::sqrt(peak * jerk);
  return {ap, ap / jerk, 2.0 * ap / jerk};
}

}  // namespace

JerkLimitedProfile::JerkLimitedProfile(double start_m, double target_m, const MoveLimits& limits)
    : start_m_(start_m),
      target_m_(target_m),
      direction_(target_m >= start_m ? 1.0 : -1.0),
      distance_m_(std::abs(target_m - start_m)) {
  const double v = limits.speed_m_s, a = limits.accel_m_s2, j = limits.jerk_m_s3;
  const double d = distance_m_;
  if (!(d > 0.0)) return;  // no distance: a move that is already over
  double peak = v;
  if (peak * phase_to(peak, a, j).duration > d) {
    // Too short to reach v: the peak speed at which the two phases alone cover d.
    const double r = ramp_speed(a, j);
    peak = 0.5 * (-r + std::sqrt(r * r + 4.0 * a * d));
    if (peak < r) peak = std::cbrt(0.25 * d * d * j);
  }
  const Phase p = phase_to(peak, a, j);
  peak_speed_m_s_ = peak;
  peak_accel_m_s2_ = p.peak_accel;
  jerk_time_s_ = p.jerk_time;
  accel_phase_s_ = p.duration;
  jerk_m_s3_ = p.jerk_time > 0.0 ? p.peak_accel / p.jerk_time : 0.0;
  cruise_time_s_ = std::max(0.0, (d - peak * p.duration) / peak);  // rounding when there is none
}

MotionSample JerkLimitedProfile::accelerating(double tau) const {
  const double tj = jerk_time_s_, ap = peak_accel_m_s2_, j = jerk_m_s3_, vp = peak_speed_m_s_;
  const double ta = accel_phase_s_;
  if (tau < tj) return {j * tau * tau * tau / 6.0, 0.5 * j * tau * tau, j * tau, j};
  if (tau <= ta - tj) {
    // Constant acceleration (a trapezoid's whole phase: T_j = 0).
    const double v1 = 0.5 * ap * tj, s1 = ap * tj * tj / 6.0, u = tau - tj;
    return {s1 + v1 * u + 0.5 * ap * u * u, v1 + ap * u, ap, 0.0};
  }
  const double sigma = ta - tau;
  return {0.5 * vp * ta - vp * sigma + j * sigma * sigma * sigma / 6.0, vp - 0.5 * j * sigma * sigma, j * sigma,
          -j};
}

MotionSample JerkLimitedProfile::at(double t_s) const {
  const double total = duration_s();
  MotionSample s;
  if (t_s >= total) {  // over (or no distance to go): at rest on the target
    s.position_m = target_m_;
    return s;
  }
  if (t_s <= 0.0) {
    s.position_m = start_m_;
    return s;
  }
  const double ta = accel_phase_s_;
  if (t_s <= ta) {
    s = accelerating(t_s);
  } else if (t_s <= ta + cruise_time_s_) {
    s = {0.5 * peak_speed_m_s_ * ta + peak_speed_m_s_ * (t_s - ta), peak_speed_m_s_, 0.0, 0.0};
  } else {
    const MotionSample mirror = accelerating(total - t_s);
    s = {distance_m_ - mirror.position_m, mirror.velocity_m_s, -mirror.accel_m_s2, mirror.jerk_m_s3};
  }
  return {start_m_ + direction_ * s.position_m, direction_ * s.velocity_m_s, direction_ * s.accel_m_s2,
          direction_ * s.jerk_m_s3};
}

}  // namespace hsa::control
