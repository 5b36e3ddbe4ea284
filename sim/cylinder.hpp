// The vertical hydraulic cylinder of Puglisi et al. (2015) lifting its load, fed by a four-way closed-centre
// valve (Puglisi et al. 2015, section 2 and Fig. 1):
//
//   m·ÿ   = Ap·(PA − α·PB) − σ_eff·ẏ − F_friction − m·g           (eq 7, load force Fe = m·g)
//   ṖA    = β/V_A(y) · (Q_A − Ap·ẏ)                               (eq 5, before linearization)
//   ṖB    = β/V_B(y) · (Q_B + α·Ap·ẏ)                             (eq 6; Q_B is flow into B)
//   Q_A, Q_B from the orifice equation at the opening x ∈ [−1, 1] (x > 0 opens P→A and B→T),
//   plus the valve's laminar null leakage, which settles the chambers to PA = α·PB when closed.
//
// m, σ_eff, β and the orifice coefficient depend on position and load (identified_parameters.hpp).
// Dry friction is Karnopp's model: the rod sticks while |ẏ| is below a threshold and the other
// forces stay under the static friction; the paper's linearization (eq 7) keeps only the viscous
// part. End stops at 0 and the full stroke are rigid and inelastic. Chamber pressures cannot fall
// below tank (cavitation); they may exceed supply briefly when the load drives the rod.
//
// Integration is classic RK4 over one step with the opening and load held (zero-order hold);
// stops, stiction and cavitation are applied between steps.
#pragma once

#include "sim/cylinder_geometry.hpp"
#include "sim/hydraulic_supply.hpp"
#include "sim/identified_parameters.hpp"

namespace hsa::sim {

struct CylinderParameters {
  CylinderGeometry geometry{};
  DynamicsOverrides dynamics{};  // none: the paper's identified m, σ_eff, β and c
  double gravity_m_per_s2 = paper::kGravity;
  // Dry friction of the seals and the linear guide. The paper identifies only the viscous part;
  // 2 N is small next to the identified dynamics and still makes the rod dwell at reversals, the
  // stick-slip the paper reports in its tracking experiment. Static and sliding friction are equal
  // on purpose: a breakaway force above the sliding one (a Stribeck drop) makes an integrating
  // position loop hunt in a stick-slip limit cycle (Armstrong-Hélouvry et al., Automatica 1994).
  // With 3 N static over 2 N sliding this model hunted at 26–79 µm peak-to-peak after every step.
  // The paper's rig settled without oscillation under the same PI (section 5, Exp. 1), so it had
  // no such drop.
  double static_friction_n = 2.0;
  double coulomb_friction_n = 2.0;
  double stick_velocity_m_per_s = 1e-4;
  // Closed-valve leakage from P to T with both control ports at their null pressures, at supply
  // pressure (a miniature two-stage servo-valve passes a few tenths of a L/min).
  double null_leakage_m3_per_s = 0.3 / 60000;

  friend bool operator==(const CylinderParameters&, const CylinderParameters&) = default;
};

struct CylinderState {
  double position_m = 0.0;
  double velocity_m_per_s = 0.0;
  double pressure_a_pa = 0.0;
  double pressure_b_pa = 0.0;
};

struct PortFlows {
  double into_a_m3_per_s;
  double into_b_m3_per_s;
};

class Cylinder {
 public:
  Cylinder(const CylinderParameters& parameters, const SupplyParameters& supply);

  // The rest state at a position: pressures holding the load, rod still.
  [[nodiscard]] CylinderState rest_state(double position_m, double load_kg) const;

  // One step of `dt` with the opening and load held. `supply_on == false` models a lost pump.
  void step(CylinderState& state, double opening, double load_kg, bool supply_on, double dt) const;

  // The time derivative of the state at fixed parameters; the dynamics step() integrates.
  // With `dry_friction == false` it is the smooth model the paper linearizes (eq 7).
  [[nodiscard]] CylinderState derivative(const CylinderState& state, const LocalParameters& local,
                                         double opening, bool supply_on, bool dry_friction = true) const;

  [[nodiscard]] PortFlows port_flows(const CylinderState& state, const LocalParameters& local, double opening,
                                     bool supply_on) const;

  [[nodiscard]] LocalParameters local_parameters(double position_m, double load_kg) const {
    return map_.at(position_m, load_kg);
  }
  [[nodiscard]] const IdentifiedParameterMap& parameter_map() const { return map_; }
  [[nodiscard]] const CylinderParameters& parameters() const { return parameters_; }
  [[nodiscard]] const SupplyParameters& supply() const { return supply_; }

 private:
  CylinderParameters parameters_;
  SupplyParameters supply_;
  IdentifiedParameterMap map_;
  double leak_conductance_;  // laminar, m³/s per Pa, per chamber (split P→port / port→T)
};

}  // namespace hsa::sim
