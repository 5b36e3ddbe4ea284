#include "sim/servo_valve.hpp"

#include <algorithm>

namespace hsa::sim {

void ServoValve::step(double command, double dt) {
  if (stuck_) {
    rate_ = 0.0;
    return;
  }
  const double w = 2.0 * std::numbers::pi * parameters_.bandwidth_hz;
  const double u = std::clamp(command, -1.0, 1.0);
  auto accel = [&](double x, double xd) { return w * w * (u - x) - 2.0 * parameters_.damping_ratio * w * xd; };
  // RK4 on (x, ẋ); ω·dt = 0.22 at the 100 µs base tick, well inside its accuracy.
  const double x0 = opening_, v0 = rate_;
  const double a1 = accel(x0, v0);
  const double x2 = x0 + dt / 2 * v0, v2 = v0 + dt / 2 * a1;
  const double a2 = accel(x2, v2);
  const double x3 = x0 + dt / 2 * v2, v3 = v0 + dt / 2 * a2;
  const double a3 = accel(x3, v3);
  const double x4 = x0 + dt * v3, v4 = v0 + dt * a3;
  const double a4 = accel(x4, v4);
  opening_ = x0 + dt / 6 * (v0 + 2 * v2 + 2 * v3 + v4);
  rate_ = v0 + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  if (opening_ > 1.0 || opening_ < -1.0) {
    opening_ = std::clamp(opening_, -1.0, 1.0);
    rate_ = 0.0;
  }
}

}  // namespace hsa::sim
