// The rig's parameters as functions of rod position and load, calibrated from the paper's
// identified Tables A1 and A2 (Puglisi et al. 2015). Table A3 is not used here: it is the check.
//
// At each of the 33 working points the paper's linear model (eqs 8, 14, 17–21) has
//     b1 = σ/m − Kp,   b0 = (Ap·Kd − σ·Kp)/m,   k01 = Ap·Kx/(m·b0).
// The simulator realizes the same valve-to-position transfer function with physical parts:
// - total moving mass m(y, L) from Table A1;
// - rod damping σ_eff = m·b1 = σ + m·|Kp|. The paper's Kp ≈ −100 1/s is a load-pressure
//   relaxation. Built as a leak it would need ≈ 85 L/min at this stiffness (the pump gives 5) and
//   would let the load sink at ≈ 0.1 m/s with the valve closed. As damping on the rod it gives the
//   same b0, b1 and k01 with nothing drawn from the pump and a load that stays put;
// - effective bulk modulus β(y, L), from the hydraulic stiffness k_h = m·b0 = Ap²·β·(1/V_A + α²/V_B).
//   It comes out at 6–18 MPa, two orders below a mineral oil's ≈ 1.5 GPa: most of the rig's
//   compliance is not the oil's (hoses, entrained air, or dead volumes larger than assumed);
// - valve flow coefficient c(y, L) of the orifice equation, from the speed gain k01 at the
//   chamber pressures that hold the load.
// What the substitution changes is the path from load force to position: the paper's zero at
// z0 = −Kp (eq 38) is not reproduced, so a P controller's steady error under gravity (eq 43) comes
// only from the valve's real null leakage and is far smaller than eq 43 predicts.
//
// Between working points the values are interpolated bilinearly in position and load; outside the
// identified range they are held at the edge in position and extrapolated linearly in load.
//
// β and c are properties of the oil and of the valve, not of the cylinder: they are calibrated
// once on the paper's own rig (its geometry, supply and gravity, the defaults of
// CylinderGeometry and SupplyParameters) and then kept whatever cylinder the simulator is given.
// A larger bore therefore stiffens the plant as k_h = Ap²·β·(1/V_A + α²/V_B) says, instead of the
// calibration absorbing it. A rig that is not the paper's may replace any of the four
// identified quantities by a constant of its own (DynamicsOverrides); the others keep the paper's.
#pragma once

#include <array>
#include <optional>

#include "sim/cylinder_geometry.hpp"
#include "sim/hydraulic_supply.hpp"
#include "sim/paper_tables.hpp"

namespace hsa::sim {

struct LocalParameters {
  double mass_kg = 0.0;
  double damping_n_s_per_m = 0.0;  // σ_eff
  double bulk_modulus_pa = 0.0;    // β
  double flow_coefficient = 0.0;   // c in Q = c·x·√Δp, m³/s per √Pa at full opening
};

// Constants that replace the paper's identified, working-point dependent values; unset keeps them.
struct DynamicsOverrides {
  std::optional<double> moving_mass_kg;  // rod, piston and carriage; the load mass adds to it
  std::optional<double> viscous_damping_n_s_per_m;  // σ_eff of eq 7
  std::optional<double> bulk_modulus_pa;            // β of eqs 5–6
  std::optional<double> flow_coefficient;           // c in Q = c·x·√Δp, m³/s per √Pa at full opening

  friend bool operator==(const DynamicsOverrides&, const DynamicsOverrides&) = default;
};

class IdentifiedParameterMap {
 public:
  explicit IdentifiedParameterMap(const DynamicsOverrides& overrides = {});

  [[nodiscard]] LocalParameters at(double position_m, double load_kg) const;
  // The value calibrated at one of the paper's working points.
  [[nodiscard]] const LocalParameters& at_working_point(std::size_t position_index,
                                                        std::size_t load_index) const {
    return points_[position_index][load_index];
  }

 private:
  std::array<std::array<LocalParameters, paper::kLoads>, paper::kWorkingPositions> points_{};
  std::optional<double> moving_mass_kg_;  // the load is added in at(), where the load is known
};

// The chamber pressures at which a closed-centre valve holds the load, given the null pressures
// the leakage settles to: PA − α·PB = m·g/Ap, shifted from the null point along the direction of
// least change. Used for calibration and to start the rig at rest.
struct HoldPressures {
  double a_pa;
  double b_pa;
};
[[nodiscard]] HoldPressures hold_pressures(const CylinderGeometry& geometry, const SupplyParameters& supply,
                                           double load_force_n);

}  // namespace hsa::sim
