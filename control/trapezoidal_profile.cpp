#include "control/trapezoidal_profile.hpp"

#include <algorithm>
#include <cmath>

namespace hsa::control {

TrapezoidalProfile::TrapezoidalProfile(double start_m, double target_m, double speed_m_s, double accel_m_s2)
    : start_m_(start_m),
      target_m_(target_m),
      direction_(target_m >= start_m ? 1.0 : -1.0),
      distance_m_(std::abs(target_m - start_m)),
      accel_m_s2_(accel_m_s2) {
  peak_speed_m_s_ = std::min(speed_m_s, std::sqrt(accel_m_s2 * distance_m_));
  if (peak_speed_m_s_ <= 0.0) return;  // no distance: a move that is already over
  accel_time_s_ = peak_speed_m_s_ / accel_m_s2;
  cruise_time_s_ = (distance_m_ - peak_speed_m_s_ * peak_speed_m_s_ / accel_m_s2) / peak_speed_m_s_;
  cruise_time_s_ = std::max(0.0, cruise_time_s_);  // rounding in the triangular case
}

double TrapezoidalProfile::travelled(double t_s) const {
  const double total = duration_s();
  if (t_s <= 0.0 || peak_speed_m_s_ <= 0.0) return 0.0;
  if (t_s >= total) return distance_m_;
  if (t_s <= accel_time_s_) return 0.5 * accel_m_s2_ * t_s * t_s;
  if (t_s <= accel_time_s_ + cruise_time_s_) {
    return 0.5 * peak_speed_m_s_ * accel_time_s_ + peak_speed_m_s_ * (t_s - accel_time_s_);
  }
  const double remaining = total - t_s;
  return distance_m_ - 0.5 * accel_m_s2_ * remaining * remaining;
}

double TrapezoidalProfile::position(double t_s) const { return start_m_ + direction_ * travelled(t_s); }

double TrapezoidalProfile::velocity(double t_s) const {
  const double total = duration_s();
  if (t_s <= 0.0 || t_s >= total || peak_speed_m_s_ <= 0.0) return 0.0;
  double speed = peak_speed_m_s_;
  if (t_s < accel_time_s_) speed = accel_m_s2_ * t_s;
  if (t_s > accel_time_s_ + cruise_time_s_) speed = accel_m_s2_ * (total - t_s);
  return direction_ * speed;
}

}  // namespace hsa::control
