// A point-to-point move with bounded speed and acceleration: the trapezoidal velocity profile.
//
// From rest at `start` to rest at `target`: accelerate at a, cruise at v, decelerate at a. When the
// distance d is too short to reach v (d < v²/a) the cruise vanishes and the peak speed is √(a·d),
// a triangle. With t_a the time to peak speed v_p = min(v, √(a·d)) and t_c = (d − v_p²/a) / v_p the
// cruise, the position at time t after the start is
//   t ≤ t_a:                s(t) = a t² / 2
//   t_a < t ≤ t_a + t_c:    s(t) = v_p² / (2a) + v_p (t − t_a)
//   then, with τ = T − t:   s(t) = d − a τ² / 2, up to T = 2 t_a + t_c; after T, s = d
// and x(t) = start + sign(target − start) · s(t). Speed and acceleration never exceed v and a.
// This is what a motion controller calls a trapezoidal move; LinuxCNC's simple_tp does the same
// per joint. Pure arithmetic: no allocation, safe to evaluate in the RT cycle.
#pragma once

namespace hsa::control {

class TrapezoidalProfile {
 public:
  TrapezoidalProfile() = default;
  // speed_m_s and accel_m_s2 must be positive and finite (the caller checks them).
  TrapezoidalProfile(double start_m, double target_m, double speed_m_s, double accel_m_s2);

  // Position t_s seconds after the start; clamped to the ends outside [0, duration].
  [[nodiscard]] double position(double t_s) const;
  // Velocity at t_s (signed), for a feedforward or a check.
  [[nodiscard]] double velocity(double t_s) const;
  [[nodiscard]] double duration_s() const { return 2.0 * accel_time_s_ + cruise_time_s_; }
  [[nodiscard]] double start_m() const { return start_m_; }
  [[nodiscard]] double target_m() const { return target_m_; }
  [[nodiscard]] double peak_speed_m_s() const { return peak_speed_m_s_; }

 private:
  // Distance covered from the start, as a positive number, at time t_s.
  [[nodiscard]] double travelled(double t_s) const;

  double start_m_ = 0.0;
  double target_m_ = 0.0;
  double direction_ = 1.0;
  double distance_m_ = 0.0;
  double accel_m_s2_ = 1.0;
  double peak_speed_m_s_ = 0.0;
  double accel_time_s_ = 0.0;
  double cruise_time_s_ = 0.0;
};

}  // namespace hsa::control
