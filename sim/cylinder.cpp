#include "sim/cylinder.hpp"

#include <algorithm>
#include <cmath>

#include "sim/orifice.hpp"

namespace hsa::sim {

Cylinder::Cylinder(const CylinderParameters& parameters, const SupplyParameters& supply)
    : parameters_(parameters),
      supply_(supply),
      map_(parameters.dynamics) {
  // Each port leaks through a P→port conductance k·G and a port→T conductance (1 − k)·G, with k
  // chosen for the null pressures of hold_pressures(). In series they pass Ps·k·(1 − k)·G from P
  // to T; both ports together pass the rated null leakage.
  const double alpha = parameters.geometry.area_ratio();
  const double k_times_one_minus_k = alpha / ((1.0 + alpha) * (1.0 + alpha));  // same for A and B
  leak_conductance_ =
      parameters.null_leakage_m3_per_s / (2.0 * supply.supply_pressure_pa * k_times_one_minus_k);
}

CylinderState Cylinder::rest_state(double position_m, double load_kg) const {
  const LocalParameters local = map_.at(position_m, load_kg);
  const HoldPressures hold =
      hold_pressures(parameters_.geometry, supply_, local.mass_kg * parameters_.gravity_m_per_s2);
  return {position_m, 0.0, hold.a_pa, hold.b_pa};
}

PortFlows Cylinder::port_flows(const CylinderState& s, const LocalParameters& local, double opening,
                               bool supply_on) const {
  const double alpha = parameters_.geometry.area_ratio();
  const double x = std::clamp(opening, -1.0, 1.0);
  const double c = local.flow_coefficient * std::abs(x);
  // Only one land to P is open at a time: P→A extending, P→B retracting.
  const double fed_port_pressure = x >= 0.0 ? s.pressure_a_pa : s.pressure_b_pa;
  const double ps = supply_on ? supply_pressure_for(supply_, c, fed_port_pressure) : 0.0;

  double into_a = 0.0;
  double into_b = 0.0;
  if (x >= 0.0) {
    into_a = orifice_flow(c, ps - s.pressure_a_pa);
    into_b = -orifice_flow(c, s.pressure_b_pa);
  } else {
    into_a = -orifice_flow(c, s.pressure_a_pa);
    into_b = orifice_flow(c, ps - s.pressure_b_pa);
  }
  const double ka = alpha / (1.0 + alpha);  // null pressure of A as a fraction of supply
  const double kb = 1.0 / (1.0 + alpha);
  const double g = leak_conductance_;
  into_a += ka * g * (ps - s.pressure_a_pa) - (1.0 - ka) * g * s.pressure_a_pa;
  into_b += kb * g * (ps - s.pressure_b_pa) - (1.0 - kb) * g * s.pressure_b_pa;
  return {into_a, into_b};
}

CylinderState Cylinder::derivative(const CylinderState& s, const LocalParameters& local, double opening,
                                   bool supply_on, bool dry_friction) const {
  const CylinderGeometry& geo = parameters_.geometry;
  const double area = geo.piston_area();
  const double alpha = geo.area_ratio();
  const double y = std::clamp(s.position_m, 0.0, geo.stroke_m);
  const double v = s.velocity_m_per_s;

  const PortFlows q = port_flows(s, local, opening, supply_on);
  const double dpa = local.bulk_modulus_pa / geo.volume_a(y) * (q.into_a_m3_per_s - area * v);
  const double dpb = local.bulk_modulus_pa / geo.volume_b(y) * (q.into_b_m3_per_s + alpha * area * v);

  // Everything but dry friction.
  double force = area * (s.pressure_a_pa - alpha * s.pressure_b_pa) - local.damping_n_s_per_m * v -
                 local.mass_kg * parameters_.gravity_m_per_s2;
  if (dry_friction) {
    if (std::abs(v) > parameters_.stick_velocity_m_per_s) {
      force -= std::copysign(parameters_.coulomb_friction_n, v);
    } else {
      // Stuck: friction cancels up to the static limit.
      force -= std::clamp(force, -parameters_.static_friction_n, parameters_.static_friction_n);
    }
  }
  // A rod against a stop cannot accelerate into it.
  if ((y <= 0.0 && force < 0.0) || (y >= geo.stroke_m && force > 0.0)) force = 0.0;

  return {v, force / local.mass_kg, dpa, dpb};
}

void Cylinder::step(CylinderState& s, double opening, double load_kg, bool supply_on, double dt) const {
  // Parameters are frozen over the step: they vary with position over millimetres, not microns.
  const LocalParameters local = map_.at(s.position_m, load_kg);
  auto add = [](const CylinderState& a, const CylinderState& d, double h) {
    return CylinderState{a.position_m + h * d.position_m, a.velocity_m_per_s + h * d.velocity_m_per_s,
                         a.pressure_a_pa + h * d.pressure_a_pa, a.pressure_b_pa + h * d.pressure_b_pa};
  };
  const CylinderState k1 = derivative(s, local, opening, supply_on);
  const CylinderState k2 = derivative(add(s, k1, dt / 2), local, opening, supply_on);
  const CylinderState k3 = derivative(add(s, k2, dt / 2), local, opening, supply_on);
  const CylinderState k4 = derivative(add(s, k3, dt), local, opening, supply_on);
  const double w = dt / 6.0;
  s.position_m += w * (k1.position_m + 2 * k2.position_m + 2 * k3.position_m + k4.position_m);
  s.velocity_m_per_s += w * (k1.velocity_m_per_s + 2 * k2.velocity_m_per_s + 2 * k3.velocity_m_per_s +
                             k4.velocity_m_per_s);
  s.pressure_a_pa += w * (k1.pressure_a_pa + 2 * k2.pressure_a_pa + 2 * k3.pressure_a_pa + k4.pressure_a_pa);
  s.pressure_b_pa += w * (k1.pressure_b_pa + 2 * k2.pressure_b_pa + 2 * k3.pressure_b_pa + k4.pressure_b_pa);

  // Cavitation: a chamber does not go below tank.
  s.pressure_a_pa = std::max(s.pressure_a_pa, 0.0);
  s.pressure_b_pa = std::max(s.pressure_b_pa, 0.0);

  // Rigid, inelastic end stops.
  const double stroke = parameters_.geometry.stroke_m;
  if (s.position_m <= 0.0) {
    s.position_m = 0.0;
    s.velocity_m_per_s = std::max(s.velocity_m_per_s, 0.0);
  } else if (s.position_m >= stroke) {
    s.position_m = stroke;
    s.velocity_m_per_s = std::min(s.velocity_m_per_s, 0.0);
  }

  // Stiction: a rod slower than the threshold whose driving force is under the static limit stops.
  if (std::abs(s.velocity_m_per_s) <= parameters_.stick_velocity_m_per_s) {
    const double alpha = parameters_.geometry.area_ratio();
    const double drive = parameters_.geometry.piston_area() * (s.pressure_a_pa - alpha * s.pressure_b_pa) -
                         local.mass_kg * parameters_.gravity_m_per_s2;
    if (std::abs(drive) <= parameters_.static_friction_n) s.velocity_m_per_s = 0.0;
  }
}

}  // namespace hsa::sim
