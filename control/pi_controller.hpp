#pragma once

#include <cstdint>
#include <limits>

#include "control/feedforward_schedule.hpp"
#include "control/motion_feedforward.hpp"

namespace hsa::control {

// Discrete PI controller of the cylinder (rod position) loop, Puglisi et al. (2015) section 4.2:
// K(s) = Kp + Ki/s, tuned there to Kp = 0.085 and Ki = 0.46 in valve opening per mm, which in SI is
// Kp = 85 m⁻¹ and Ki = 460 m⁻¹s⁻¹.
//
// Algorithm, once per sample period T, with setpoint r(k) and measured rod position y(k):
//
//   r_l(k) = r_l(k-1) + clamp(r(k) - r_l(k-1), -v_max·T, +v_max·T)    setpoint rate limit
//   e(k)   = dz(r_l(k) - y(k), dead_band)                               error dead band
//   i(k)   = i(k-1) + Ki·T·dz(e(k), integral_dead_band)   (skipped while frozen, see anti-windup,
//                                                          and while a planned move is under way)
//   u(k)   = clamp(Kp·e(k) + i(k) + u_ff(k), -u_max, +u_max),   u_ff = Kv·v_ff + Ka·a_ff + Kj·j_ff
//
// v_ff, a_ff, j_ff are the setpoint's velocity, acceleration and jerk, supplied by whoever plans
// the trajectory (a move's profile gives all three, a streamed setpoint at most v_ff): the opening
// u_ff is what the inverted plant needs to follow them (control/motion_feedforward.hpp, Puglisi et
// al. 2015 eq 38), so the rod moves without waiting for an error to build up (1/Kv is the rod
// speed at full opening). A gain of 0, the default here, turns its term off; the anti-windup below
// sees the feed-forward as part of the output. With a feed-forward schedule the gains are those of
// the plant at the setpoint's position r_l(k) (control/feedforward_schedule.hpp).
//
// The integral is discretized by backward Euler, K(z) = Kp + Ki·T·z/(z - 1): the error of this
// sample acts on this sample's output, which is the usual choice when the output is written within
// the same tick as the measurement is read. At 1 kHz the loop crossover (about 20 rad/s) is far
// below the Nyquist frequency, so the choice of rule does not move the closed-loop poles visibly.
//
// dz(e, w) is a continuous dead band: zero inside ±w, shifted by w outside, so nothing steps at its
// edges. Both bands default to zero, which is the paper's PI.
// - dead_band silences the whole controller near the setpoint.
// - integral_dead_band stops only the integrator near the setpoint; the proportional term still
//   acts on the full error. This is what stops a stick-slip hunt (tools/hsa_analyze/experiments.hpp):
//   while dry friction holds the rod, the chamber pressures integrate the valve opening, so an
//   integral that keeps ramping on a stuck error of a few µm builds up an excess opening that is
//   released as a slip past the setpoint, and the cycle repeats the other way. With the integral
//   parked inside the band, the proportional term alone moves the rod the last few µm and it comes
//   to rest within ±integral_dead_band.
//
// Anti-windup by conditional integration: the integral step is skipped when the output would be
// clamped and the error pushes further into that clamp (e > 0 at +u_max, e < 0 at -u_max). The
// integrator then holds, and the loop leaves saturation as soon as the error changes sign, without
// first unwinding a stored integral. saturated() reports the last sample; saturation_count() counts
// saturated samples since construction, for telemetry.
//
// Conditional integration during a planned move (SetpointMotion::planned, a MOVE_TO's profile, or
// the path hsad's stream limiter plans while it lags a stream):
// the integral step is skipped until the profile has ended. The integrator is there for the
// static opening (the load, the valve's null offset), which it holds from before the move; the
// feed-forward supplies the motion's opening. What the feed-forward's model misses during the
// move (the rod speed per opening differs over stroke, load and direction: k01 224-294 mm/s in
// Table A3, and gravity helps one way and hinders the other) is proportional to the speed and
// vanishes when the move stops: an integrator that learnt it during the move would release it as
// overshoot at the end. Kp alone holds that error during the move (the following error is
// u_miss/Kp), and the integrator resumes from its pre-move value once the profile ends.
//
// Skipped samples: update(..., periods) with periods = m > 1 takes one step of m·T, as when the
// caller's schedule skipped m − 1 samples: the rate limit allows v_max·m·T and the integral grows
// by Ki·m·T·dz(e). For a constant error this is exactly what m steps of T would give (backward
// Euler integrates a constant exactly), up to the rounding of one product against m sums. With
// m = 1 the arithmetic is the same as the single-period form, bit for bit.
//
// Bumpless activation: activate(y, u) sets the rate-limited setpoint to the measured position y
// (so e = 0) and the integral to the output u the valve currently sees, so the first output equals
// u wherever the rod is. From there the setpoint ramps towards the commanded one at v_max, so even
// an activation far from the commanded setpoint produces no step. With v_max infinite the
// commanded setpoint acts at once: that is a setpoint step, which is the caller's choice.
//
// Bumpless gain change: set_gains(Kp', Ki') keeps the output of the last sample by re-solving it
// for the integral, the same transfer as activation:
//   i' = u(k) - Kp'·e(k) - u_ff(k)
// so that Kp'·e(k) + i' + u_ff(k) = u(k). The next sample starts from there, and its output
// moves from u(k) by what the new gains make of the error's change, as any sample does. The
// integral is kept in output units, so a change of Ki alone needs no correction. Setpoint limiter,
// dead bands and saturation counters are left as they are.
struct PiParams {
  double kp = 85.0;          // m⁻¹: valve opening per metre of error
  double ki = 460.0;         // m⁻¹s⁻¹
  double period_s = 1e-3;    // T: the cylinder loop runs at 1 kHz
  double output_limit = 1.0;  // u_max: the valve opening range is [-1, 1]
  double max_setpoint_rate_m_s = std::numeric_limits<double>::infinity();  // v_max
  double dead_band_m = 0.0;
  double integral_dead_band_m = 0.0;
  double velocity_feedforward = 0.0;      // Kv: opening per m/s of setpoint velocity, >= 0 (0 = off)
  double acceleration_feedforward = 0.0;  // Ka: opening per m/s² of setpoint acceleration, >= 0
  double jerk_feedforward = 0.0;          // Kj: opening per m/s³ of setpoint jerk, >= 0
  // When not empty, Kv, Ka and Kj at the rate-limited setpoint's position come from it instead of
  // the three gains above (control/feedforward_schedule.hpp).
  FeedforwardSchedule feedforward_schedule{};
  bool hold_integral_while_planned = true;  // conditional integration during a planned move (below)

  bool operator==(const PiParams&) const = default;
};

class PiController {
 public:
  // Throws std::invalid_argument for a non-positive period or limit, negative gains, rate or dead
  // bands.
  explicit PiController(const PiParams& params);

  // Bumpless (re)start at the measured rod position with the opening currently applied.
  void activate(double measured_position_m, double current_output = 0.0) noexcept;

  // Bumpless change of Kp and Ki (see above). Returns false, changing nothing, for a gain the
  // constructor would refuse (negative, NaN) or an infinite one. Never throws and allocates
  // nothing, so it runs on the RT thread.
  [[nodiscard]] bool set_gains(double kp, double ki) noexcept;

  // One sample: returns the valve opening u in [-output_limit, +output_limit]. velocity_ff_m_s is
  // the setpoint's velocity (0 when the caller has none).
  // `periods` (>= 1; 0 counts as 1) is the time since the last sample in periods T.
  double update(double setpoint_m, double measured_position_m, double velocity_ff_m_s = 0.0,
                std::uint64_t periods = 1) noexcept {
    return update(setpoint_m, measured_position_m, SetpointMotion{velocity_ff_m_s, 0.0, 0.0}, periods);
  }
  // The same with the setpoint's acceleration and jerk too, for the feed-forward.
  double update(double setpoint_m, double measured_position_m, const SetpointMotion& motion,
                std::uint64_t periods = 1) noexcept;

  [[nodiscard]] double output() const noexcept { return output_; }
  [[nodiscard]] double integral() const { return integral_; }
  [[nodiscard]] double limited_setpoint() const noexcept { return limited_setpoint_; }
  [[nodiscard]] double error() const { return error_; }
  [[nodiscard]] bool saturated() const noexcept { return saturated_; }
  [[nodiscard]] std::uint64_t saturation_count() const { return saturation_count_; }
  [[nodiscard]] const PiParams& params() const noexcept { return params_; }

 private:
  FeedforwardGains feedforward_gains() noexcept;

  PiParams params_;
  bool has_feedforward_ = false;  // a feed-forward gain or schedule: u_ff is not 0 by construction
  // The schedule's gains at the position of these bits, when valid (feedforward_gains()).
  bool scheduled_valid_ = false;
  std::uint64_t scheduled_position_bits_ = 0;
  FeedforwardGains scheduled_gains_{};
  double limited_setpoint_ = 0.0;
  double integral_ = 0.0;
  double error_ = 0.0;
  double output_ = 0.0;
  double feedforward_ = 0.0;  // u_ff of the last sample
  bool saturated_ = false;
  std::uint64_t saturation_count_ = 0;
};

}  // namespace hsa::control
