// The valve opening a planned motion needs, from the inverted cylinder plant.
//
// Puglisi et al. (2015) eqs 38 and 41 give the rod position Y from the normalized valve opening Xv,
// at one working point and without external force change:
//   Y(s) = k01·b0 / (s·(s² + b1·s + b0)) · Xv(s)
// Inverting it, Xv(s) = (s³ + b1·s² + b0·s) / (k01·b0) · Y(s), and since s·Y, s²·Y and s³·Y are
// the rod's velocity v, acceleration a and jerk j, the opening that makes the rod follow a motion
// whose derivatives are known is
//   u_ff = v / k01 + (b1 / (k01·b0))·a + (1 / (k01·b0))·j = Kv·v + Ka·a + Kj·j.
// - Kv = 1/k01: k01 is the rod speed at full opening, so this is the opening of a steady speed.
// - Ka = b1/(k01·b0): the opening the hydraulic spring needs to build the pressure that
//   accelerates the mass (for a valve of flow gain Kx, b1/b0 ≈ the flow a pressure change takes).
// - Kj = 1/(k01·b0): the oil compressed while the pressure ramps; small next to the others.
// The plan supplies v, a and j (control/jerk_limited_profile.hpp); a streamed setpoint supplies v
// alone. The feedback PI (control/pi_controller.hpp) only corrects what the model misses (the
// plant varying over stroke and load, friction), so the move's error stays small and its
// integrator need not carry the cruise opening, which is what an overshoot is made of.
//
// The gains are configuration values ([axes.pi] velocity_feedforward, acceleration_feedforward,
// jerk_feedforward). Their defaults come from the paper's nominal plant P0 (eq 52, the plant
// identified at 6 kg and 120 mm; control/plant_table.hpp), via plant_inverse_gains() below.
// Pure arithmetic: no allocation, safe to evaluate in the RT cycle.
#pragma once

#include "control/plant_table.hpp"

namespace hsa::control {

struct FeedforwardGains {
  double velocity = 0.0;  // Kv, opening per m/s (s/m)
  double accel = 0.0;     // Ka, opening per m/s² (s²/m)
  double jerk = 0.0;      // Kj, opening per m/s³ (s³/m)

  bool operator==(const FeedforwardGains&) const = default;
};

// The derivatives of the setpoint a feed-forward acts on; 0 where the setpoint has none.
struct SetpointMotion {
  double velocity_m_s = 0.0;
  double accel_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;
  // The setpoint follows a path hsad planned and is still under way (a MOVE_TO's profile, or the
  // stream limiter's while it lags the stream): the feedback PI holds its integrator
  // (pi_controller.hpp, conditional integration).
  bool planned = false;
};

// u_ff = Kv·v + Ka·a + Kj·j. A gain of 0 contributes nothing whatever the derivative (an
// unused term cannot turn a non-finite input into the output).
[[nodiscard]] constexpr double feedforward_opening(const FeedforwardGains& k, const SetpointMotion& m) noexcept {
  double u = 0.0;
  if (k.velocity != 0.0) u += k.velocity * m.velocity_m_s;
  if (k.accel != 0.0) u += k.accel * m.accel_m_s2;
  if (k.jerk != 0.0) u += k.jerk * m.jerk_m_s3;
  return u;
}

// The gains that invert `plant` (gain = k01·b0 in mm·s⁻³, Table A3's units), in SI: a plant in
// mm per unit opening is 1e-3 times that in m, so each gain in s^n/m is 1e3 times the mm one.
[[nodiscard]] constexpr FeedforwardGains plant_inverse_gains(const CylinderPlant& plant) noexcept {
  return {1e3 * plant.b0 / plant.gain, 1e3 * plant.b1 / plant.gain, 1e3 / plant.gain};
}

// The paper's nominal plant inverted: Kv ≈ 4.467 s/m, Ka ≈ 0.0524 s²/m, Kj ≈ 5.81e-4 s³/m.
inline constexpr FeedforwardGains kNominalFeedforward = plant_inverse_gains(kNominalPlant);

}  // namespace hsa::control
