// The single-solenoid proportional valve of Canuto et al. (2014, section 2): a current
// regulator feeding a solenoid whose force drives a spring-returned plunger and spool.
//
//   current regulator (eq 1)   I(t) = I_ref(t - tau) + e(t),   |e| <= 1.5 mA,   0 <= I_ref <= I_max
//   magnetic hysteresis (eq 6) p = dead-band (play) of width w on I,   tau_a dc/dt = p - c
//   solenoid force (eq 5, 6)   F_s = K_f c
//   spool (eqs 2, 3)           m dv/dt = F_s - K (x - X_min) - b v - F_c sgn(v)
//                              X_min <= x <= X_max
//
// x is measured from hydraulic zero. The spring is relaxed at the rest stop X_min, so eq 2's
// preload K X_0 is K (0 - X_min): that is what the solenoid must balance to hold x = 0 (eq 5).
//
// Simplifications, and why they are safe for a controller test bench:
// - The magnetic force does not depend on x (eq 6's F_s(x, c)): the paper's magnetic circuit is
//   shaped to make it nearly constant over the working stroke.
// - The fluid forces F_f and the LuGre friction F_a (eqs 2, 4) become viscous damping plus Coulomb
//   friction with stiction. LuGre's pre-sliding stiffness would need a step far below 1e-4 s; the
//   Coulomb model keeps what a controller notices: a small force band in which the spool sticks.
// - The dead band's rising edge lags the current by the full width w and its falling edge follows
//   the current (c <= I): zero current gives zero force, so the spring always returns the spool to
//   X_min, as the paper's fail-to-rest valve does. Which edge is "the" bias current is not unique
//   (eq 5, item 5); bias_current() returns the centre of the band.
//
// Everything is allocated in the constructor; step() neither allocates nor throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace hsa::sim {

struct ProportionalValveParameters {
  // Current regulator (eq 1).
  double current_delay_s = 0.2e-3;     // tau: the regulated loop's pure delay
  double current_error_max_a = 1.5e-3; // bound of the uniformly distributed current error e
  double current_max_a = 3.0;          // I_max; references are clamped to [0, I_max]

  // Magnetic hysteresis (eq 6).
  double hysteresis_width_a = 0.3;  // full width of the dead band (about 10 % of I_max)
  double magnetic_lag_s = 1.5e-3;   // tau_a, 1-2 ms in the paper

  // Force constant K_f. The paper's average flux density (phi ~ 35 N/A, section 3.5) would put
  // the bias current near 0.85 A and use only a third of the current range. 18 N/A puts the bias
  // current mid-range (about 1.52 A) and still reaches X_max at about 2.36 A on the rising edge,
  // leaving 0.64 A of authority to push against the end stop and to overcome the dead band.
  double force_constant_n_per_a = 18.0;

  // Plunger and spool (eqs 2, 3).
  double moving_mass_kg = 0.1;       // m
  double natural_frequency_hz = 50.0;  // f0 = sqrt(K/m) / (2 pi): K = m (2 pi f0)^2 ~ 9870 N/m
  // Fluid damping only: oil shear in the spool clearance and transient flow forces are weak. 0.3
  // leaves the 50 Hz mode clearly underdamped (37 % overshoot), which is why the paper's analogue
  // PIDD^2 needs its velocity and acceleration feedback; it still dies out within 2-3 periods.
  double damping_ratio = 0.3;
  // Sliding friction of the plunger on its self-lubricating liner. 0.2 N is a stick band of
  // +-20 um in position (+-11 mA of current): small against the 5.4 N dead band, but enough that a
  // position loop without integral action is left with a visible error.
  double coulomb_friction_n = 0.2;
  double stroke_min_m = -2.5e-3;  // X_min: rest stop, where the return spring is relaxed
  double stroke_max_m = 1.25e-3;  // X_max: end stop

  // Spool travel from hydraulic zero at which a port is fully open, see opening().
  double opening_span_m = 1.25e-3;
  // Below this position the spool is in its fail-safe zone: the lands close again and both
  // control ports are blocked on the rest stop, see opening().
  double fail_safe_closed_m = -1.875e-3;

  std::uint64_t seed = 1;  // seeds the current error e

  friend bool operator==(const ProportionalValveParameters&, const ProportionalValveParameters&) = default;
};

class ProportionalValve {
 public:
  // step_s: the fixed step of every step() call, in (0, current_delay_s]. The current delay is
  // rounded to whole steps; the spool is integrated in substeps of at most 25 us.
  // Throws std::invalid_argument on a step or parameter outside its range.
  ProportionalValve(const ProportionalValveParameters& parameters, double step_s);

  // Restarts the model as freshly constructed (random sequence included), at rest at
  // spool_position_m (clamped to the stroke), in equilibrium: the force-equivalent current balances
  // the spring and the regulator holds the centre of the dead band around it, so step() with
  // hold_current(x) keeps the spool there. The constructor does reset(stroke_min_m): de-energized,
  // spool on its rest stop, ports blocked (opening() == 0).
  void reset(double spool_position_m);

  // Advances by step_s with the solenoid current reference I_ref (A) held over the step. The
  // reference reaches the solenoid current_delay_s later (eq 1): the value given to the k-th call
  // shows in current() after call k + current_delay_s / step_s - 1, and drives the force from then.
  void step(double current_reference_a);

  // A seized spool: it stays where it is (velocity 0) while the current and the magnetics go on.
  void set_stuck(bool stuck) {
    stuck_ = stuck;
    if (stuck) {
      v_ = 0.0;
    }
  }
  [[nodiscard]] bool stuck() const { return stuck_; }

  [[nodiscard]] double position() const { return x_; }          // spool position x, m
  [[nodiscard]] double velocity() const { return v_; }          // spool velocity, m/s
  [[nodiscard]] double current() const { return current_; }     // measured solenoid current I, A
  [[nodiscard]] double force_current() const { return c_; }     // force-equivalent current c, A

  // Normalized flow opening in [-1, 1] seen by the cylinder ports: x / opening_span_m in the
  // control stroke ±1.25 mm. The spool is taken as zero-lapped with ports symmetric about hydraulic
  // zero. The extra travel down to the rest stop is a fail-safe position, as single-solenoid valves
  // that drive a vertical load are built: the opening falls back from −1 at −1.25 mm to 0 at
  // fail_safe_closed_m and stays blocked to −2.5 mm, so a de-energized valve holds the load instead
  // of lowering it at full speed. A valve loop keeps its spool reference inside ±1.25 mm.
  [[nodiscard]] double opening() const;

  // The current that holds the spool at x (centre of the dead band around the balancing c); at
  // x = 0 this is the bias current I_0 of eq 5. Approached from below the spool stops at x only at
  // hold_current + w/2, approached from above at hold_current - w/2.
  [[nodiscard]] double hold_current(double spool_position_m) const;
  [[nodiscard]] double bias_current() const { return hold_current(0.0); }

  [[nodiscard]] double spring_stiffness() const { return stiffness_; }  // K, N/m
  [[nodiscard]] double step_s() const { return step_s_; }
  [[nodiscard]] const ProportionalValveParameters& parameters() const { return p_; }

 private:
  void advance_spool(double h);

  ProportionalValveParameters p_;
  double step_s_;
  int substeps_;
  double substep_s_;
  double stiffness_;        // K
  double damping_;          // b
  double lag_gain_;         // exact first-order lag over one substep: 1 - exp(-h / tau_a)

  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> current_error_;
  std::vector<double> reference_delay_;  // the last round(tau / step_s) references, ring buffer
  std::size_t delay_head_ = 0;           // oldest entry

  double current_ = 0.0;  // I: measured, and driving the solenoid during the next step
  double play_ = 0.0;     // dead-band output b_s(I)
  double c_ = 0.0;
  double x_ = 0.0;
  double v_ = 0.0;
  bool stuck_ = false;
};

}  // namespace hsa::sim
