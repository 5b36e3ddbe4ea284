// Shapes a streamed position setpoint so that the rod is never asked for more speed or
// acceleration than the axis has: the time-optimal follower of LinuxCNC's `limit3` component
// (position, speed and acceleration bounds), in the discrete form of Zanasi, Guarino Lo Bianco
// and Tonielli, "Nonlinear filters for the generation of smooth trajectories", Automatica 36
// (2000) 439-448, second-order filter.
//
// A streamed setpoint (a sine, a step, whatever a program sends) is the operator's wish, not a
// trajectory the valve can follow: a 100 mm step asks for infinite speed, a 50 mm sine at 3 Hz
// for 0.94 m/s. Fed straight to the PI, either saturates the valve and faults the axis. The
// limiter's output x follows the target r as closely as the bounds allow, and exactly once the
// target itself moves within them; its velocity v and acceleration a are the feed-forward's.
//
// Algorithm, once per step of T seconds, speed bound V, acceleration bound U, target r (where the
// output should be at the end of the step) moving at ṙ (clamped to ±V: a faster target cannot be
// matched), output x and velocity v at the start of the step:
//   e = (x − (r − ṙ·T))/U,   ė = (v − ṙ)/U                   error at the step's start, in units of U
//   z = (e/T + ė/2)/T,   ż = ė/T                             the same, in steps
//   m = ⌊(1 + √(1 + 8|z|))/2⌋                                steps of full braking left
//   σ = ż + z/m + (m − 1)/2 · sgn(z)                         distance from the switching curve
//   u = −U · sat(σ)                                          acceleration of this step
//   v⁺ = clamp(v + T·u, −V, V),   x⁺ = x + T·(v + v⁺)/2
// σ is 0 on the discrete braking curve (the states from which braking at U in whole steps stops
// on the target), so |σ| ≥ 1 brakes or accelerates at the bound (bang-bang, which is what makes
// it time-optimal) and |σ| < 1 lands with a smaller acceleration instead of chattering around the
// target. The paper stops accelerating once |v| is within T·U of V; the clamp lets it cruise at V
// itself. Since |v⁺ − v| ≤ T·U and |v⁺| ≤ V each step, the finite differences of x are within
// the bounds: (x⁺ − x)/T is the mean of two velocities ≤ V, and the second difference is the mean
// of two accelerations ≤ U. Once x⁺ and v⁺ are within rounding (1e-14 m) of the target and its
// velocity, they are set to them, so a static target is held exactly.
//
// Position bounds (the soft limits): the target is clamped into [low, high], and when the output,
// stopping from where the next step takes it, would pass a bound, the limiter aims at that bound
// at rest instead of the target (as limit3 does): a target that runs into a soft limit and stops
// there cannot carry the output past it.
//
// A step that is refused (non-finite target or velocity, a non-positive or non-finite T) changes
// nothing. Pure arithmetic: no allocation, no clock; safe in the RT cycle.
#pragma once

namespace hsa::control {

struct SetpointLimits {
  double speed_m_s = 0.0;   // V > 0, finite
  double accel_m_s2 = 0.0;  // U > 0, finite
  double low_m = -1e300;    // position bounds, low < high
  double high_m = 1e300;
};

class SetpointLimiter {
 public:
  SetpointLimiter() = default;
  // Throws std::invalid_argument for a non-positive or non-finite speed or acceleration, or
  // bounds that are not finite with low < high.
  explicit SetpointLimiter(const SetpointLimits& limits);

  // Starts from x (clamped into the bounds) moving at v (clamped to ±V), without acceleration.
  void reset(double position_m, double velocity_m_s = 0.0) noexcept;

  // One step of period_s towards `target_m`, which moves at target_velocity_m_s. Returns false,
  // changing nothing, for non-finite input or a period that is not positive and finite.
  bool step(double target_m, double target_velocity_m_s, double period_s) noexcept;

  [[nodiscard]] double position_m() const noexcept { return x_; }
  [[nodiscard]] double velocity_m_s() const noexcept { return v_; }
  [[nodiscard]] double accel_m_s2() const noexcept { return a_; }
  // The (clamped) target of the last step minus the output: how far the output lags.
  [[nodiscard]] double lag_m() const noexcept { return lag_m_; }
  [[nodiscard]] const SetpointLimits& limits() const noexcept { return limits_; }

 private:
  SetpointLimits limits_{1.0, 1.0};
  double x_ = 0.0;
  double v_ = 0.0;
  double a_ = 0.0;
  double lag_m_ = 0.0;
};

}  // namespace hsa::control
