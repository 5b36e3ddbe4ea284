// Geometry of the paper's double-acting cylinder (CylVal 300-series, 304 mm stroke) and the oil
// volumes it traps. The paper gives the stroke only; bore, rod and dead volumes are chosen here:
// - a 25 mm bore makes the identified no-load speed gain k01 ≈ 0.24 m/s (Table A3) need the
//   E050's rated 6.9 L/min at full opening, and the 5 L/min pump cap extension at ≈ 0.17 m/s;
// - a 12 mm rod gives the area ratio α = 0.77 of a standard differential cylinder;
// - 100 mm of equivalent dead length per side (hoses, manifold, ports) makes the position
//   dependence of the hydraulic stiffness, ∝ 1/V_A + α²/V_B, match Table A2's Kd: with it the
//   effective bulk modulus that reproduces Kd varies by < 4 % along the stroke at each load.
#pragma once

#include <numbers>

namespace hsa::sim {

struct CylinderGeometry {
  double stroke_m = 0.304;
  double bore_m = 0.025;
  double rod_m = 0.012;
  double dead_length_m = 0.100;

  friend bool operator==(const CylinderGeometry&, const CylinderGeometry&) = default;

  [[nodiscard]] double piston_area() const { return std::numbers::pi / 4.0 * bore_m * bore_m; }
  // α of the paper: annulus area over piston area.
  [[nodiscard]] double area_ratio() const { return 1.0 - (rod_m * rod_m) / (bore_m * bore_m); }
  [[nodiscard]] double volume_a(double position_m) const {
    return piston_area() * (dead_length_m + position_m);
  }
  [[nodiscard]] double volume_b(double position_m) const {
    return area_ratio() * piston_area() * (dead_length_m + stroke_m - position_m);
  }
};

}  // namespace hsa::sim
