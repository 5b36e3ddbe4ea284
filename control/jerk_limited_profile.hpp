// A point-to-point move with bounded speed, acceleration and jerk: the S-curve (seven-segment)
// profile a motion controller plans a move with.
//
// From rest at `start` to rest at `target`, distance d, with bounds v (speed), a (acceleration)
// and j (jerk). The acceleration phase reaches the peak speed v_p with the peak acceleration a_p:
//   jerk +j for T_j = a_p / j,  acceleration a_p for T_ca,  jerk −j for T_j,
// so the phase lasts T_a = 2 T_j + T_ca and covers v_p · T_a / 2 (it is point-symmetric about its
// middle). Two cases:
//   v_p ≥ a²/j:  a_p = a, T_j = a/j, T_ca = v_p/a − a/j, T_a = v_p/a + a/j
//   v_p < a²/j:  a_p = √(v_p·j), T_j = a_p/j, T_ca = 0, T_a = 2 T_j (a is never reached)
// The deceleration phase mirrors it in time; between them the rod cruises at v_p for
// T_c = (d − v_p·T_a) / v_p. When d is too short to reach v (v·T_a(v) > d) there is no cruise and
// v_p solves v_p·T_a(v_p) = d:
//   v_p = (−a²/j + √(a⁴/j² + 4·a·d)) / 2    if that is ≥ a²/j (the acceleration reaches a)
//   v_p = (d²·j / 4)^(1/3)                  otherwise
// Within the acceleration phase, with τ the time into it:
//   τ < T_j:                 jerk  j,  acc j τ,   vel j τ²/2,                  pos j τ³/6
//   T_j ≤ τ ≤ T_j + T_ca:    jerk  0,  acc a_p,   vel v_1 + a_p (τ − T_j),     pos s_1 + v_1 (τ − T_j) + a_p (τ − T_j)²/2
//   then, σ = T_a − τ:       jerk −j,  acc j σ,   vel v_p − j σ²/2,            pos v_p T_a/2 − v_p σ + j σ³/6
// with v_1 = a_p T_j / 2 and s_1 = a_p T_j² / 6. In the deceleration phase, τ' = T − t from the
// end T = 2 T_a + T_c: pos d − s(τ'), vel v(τ'), acc −acc(τ'), jerk jerk(τ'). The position is
// x(t) = start + sign(target − start) · s(t), and so are its derivatives.
//
// An infinite jerk bound gives T_j = 0: the trapezoidal profile (accelerate at a, cruise,
// decelerate), which is what the jerk bound improves on. A trapezoid's acceleration steps from 0
// to a, and a rod driven by a valve (a third-order plant, Puglisi et al. 2015 eq 38) can only
// follow that step through its hydraulic resonance; a finite jerk makes the acceleration a ramp
// the plant can follow, and makes the jerk finite so that a feed-forward through the inverted
// plant (control/motion_feedforward.hpp) is bounded. This is the profile of LinuxCNC's and most
// drives' "S-curve" moves (e.g. Biagiotti & Melchiorri, Trajectory Planning for Automatic
// Machines and Robots, 2008, section 3.4, the double-S trajectory with zero end velocities).
//
// Pure arithmetic: no allocation, no clock, safe to evaluate in the RT cycle.
#pragma once

namespace hsa::control {

// The bounds of a move. speed and accel must be positive and finite, jerk positive (infinite:
// a trapezoid); the caller checks them.
struct MoveLimits {
  double speed_m_s = 0.0;
  double accel_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;
};

// The setpoint of a move at one instant, signed.
struct MotionSample {
  double position_m = 0.0;
  double velocity_m_s = 0.0;
  double accel_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;
};

class JerkLimitedProfile {
 public:
  JerkLimitedProfile() = default;
  JerkLimitedProfile(double start_m, double target_m, const MoveLimits& limits);

  // Position and its derivatives t_s seconds after the start; at rest on the ends outside
  // [0, duration].
  [[nodiscard]] MotionSample at(double t_s) const;
  [[nodiscard]] double position(double t_s) const { return at(t_s).position_m; }
  [[nodiscard]] double velocity(double t_s) const { return at(t_s).velocity_m_s; }

  [[nodiscard]] double duration_s() const { return 2.0 * accel_phase_s_ + cruise_time_s_; }
  [[nodiscard]] double start_m() const { return start_m_; }
  [[nodiscard]] double target_m() const { return target_m_; }
  [[nodiscard]] double peak_speed_m_s() const { return peak_speed_m_s_; }
  [[nodiscard]] double peak_accel_m_s2() const { return peak_accel_m_s2_; }

 private:
  // Distance and derivatives, positive, τ seconds into the acceleration phase.
  [[nodiscard]] MotionSample accelerating(double tau_s) const;

  double start_m_ = 0.0;
  double target_m_ = 0.0;
  double direction_ = 1.0;
  double distance_m_ = 0.0;
  double jerk_m_s3_ = 0.0;        // the jerk of the ramps; 0 when they take no time (a trapezoid)
  double peak_speed_m_s_ = 0.0;
  double peak_accel_m_s2_ = 0.0;
  double jerk_time_s_ = 0.0;      // T_j
  double accel_phase_s_ = 0.0;    // T_a
  double cruise_time_s_ = 0.0;    // T_c
};

}  // namespace hsa::control
