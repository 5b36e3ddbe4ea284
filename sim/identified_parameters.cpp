#include "sim/identified_parameters.hpp"

#include <algorithm>
#include <cmath>

namespace hsa::sim {
namespace {

// Where a value lies between two grid nodes: lower index and weight of the upper node.
struct Bracket {
  std::size_t lower;
  double weight;
};

Bracket bracket_position(double position_mm) {
  const auto& rows = paper::kTableA1;
  if (position_mm <= rows.front().position_mm) return {0, 0.0};
  if (position_mm >= rows.back().position_mm) return {rows.size() - 2, 1.0};
  std::size_t i = 0;
  while (rows[i + 1].position_mm < position_mm) ++i;
  return {i, (position_mm - rows[i].position_mm) / (rows[i + 1].position_mm - rows[i].position_mm)};
}

// Loads past the table are extrapolated from its last segment; the weight is then > 1.
Bracket bracket_load(double load_kg) {
  const auto& loads = paper::kLoadKg;
  const std::size_t i = load_kg < loads[1] ? 0 : 1;
  return {i, (load_kg - loads[i]) / (loads[i + 1] - loads[i])};
}

LocalParameters blend(const LocalParameters& a, const LocalParameters& b, double w) {
  return {a.mass_kg + w * (b.mass_kg - a.mass_kg),
          a.damping_n_s_per_m + w * (b.damping_n_s_per_m - a.damping_n_s_per_m),
          a.bulk_modulus_pa + w * (b.bulk_modulus_pa - a.bulk_modulus_pa),
          a.flow_coefficient + w * (b.flow_coefficient - a.flow_coefficient)};
}

}  // namespace

HoldPressures hold_pressures(const CylinderGeometry& geometry, const SupplyParameters& supply,
                             double load_force_n) {
  const double alpha = geometry.area_ratio();
  // Null pressures: the leakage splits so that PA = α·PB with the valve centred (eq 8 with PL → 0).
  const double pa_null = supply.supply_pressure_pa * alpha / (1.0 + alpha);
  const double pb_null = supply.supply_pressure_pa / (1.0 + alpha);
  const double load_pressure = load_force_n / geometry.piston_area();
  return {pa_null + load_pressure / (1.0 + alpha * alpha),
          pb_null - alpha * load_pressure / (1.0 + alpha * alpha)};
}

IdentifiedParameterMap::IdentifiedParameterMap(const DynamicsOverrides& overrides)
    : moving_mass_kg_(overrides.moving_mass_kg) {
  // The paper's rig, on which β and c are calibrated (see the header).
  const CylinderGeometry geometry{};
  const SupplyParameters supply{};
  const double gravity = paper::kGravity;
  const double area = geometry.piston_area();
  const double alpha = geometry.area_ratio();
  for (std::size_t i = 0; i < paper::kWorkingPositions; ++i) {
    const double y = paper::kTableA1[i].position_mm * 1e-3;
    for (std::size_t j = 0; j < paper::kLoads; ++j) {
      const paper::Motion& motion = paper::kTableA1[i].by_load[j];
      const paper::Sensitivity& s = paper::kTableA2[i].by_load[j];
      const double m = motion.mass_kg;
      const double sigma = motion.viscous_n_s_per_m;
      // eqs 19–21 with the paper's own constant Ap ≈ 127: these give the transfer function the
      // tables identified, in 1/s, 1/s² and mm/s.
      const double b1 = sigma / m - s.kp;
      const double b0 = (paper::kAreaConstant * s.kd - sigma * s.kp) / m;
      const double k01 = paper::kAreaConstant * s.kx / (m * b0);

      LocalParameters& p = points_[i][j];
      p.mass_kg = m;
      p.damping_n_s_per_m = m * b1;
      const double stiffness = m * b0;  // N/m
      const double va = geometry.volume_a(y);
      const double vb = geometry.volume_b(y);
      p.bulk_modulus_pa = stiffness / (area * area * (1.0 / va + alpha * alpha / vb));
      // Speed gain at the hold point: Ap·v = c·x·(β/V_A·√(Ps−PA) + α·β/V_B·√PB)·Ap/k_h. Extending
      // opens P→A and B→T, the lands that decide the gain for small positive openings.
      const HoldPressures hold = hold_pressures(geometry, supply, m * gravity);
      const double kx_per_c = p.bulk_modulus_pa / va * std::sqrt(supply.supply_pressure_pa - hold.a_pa) +
                              alpha * p.bulk_modulus_pa / vb * std::sqrt(hold.b_pa);
      const double kx_si = (k01 * 1e-3) * stiffness / area;  // Pa/s per unit opening
      p.flow_coefficient = kx_si / kx_per_c;

      if (overrides.viscous_damping_n_s_per_m) p.damping_n_s_per_m = *overrides.viscous_damping_n_s_per_m;
      if (overrides.bulk_modulus_pa) p.bulk_modulus_pa = *overrides.bulk_modulus_pa;
      if (overrides.flow_coefficient) p.flow_coefficient = *overrides.flow_coefficient;
    }
  }
}

LocalParameters IdentifiedParameterMap::at(double position_m, double load_kg) const {
  const Bracket y = bracket_position(position_m * 1e3);
  const Bracket l = bracket_load(std::max(load_kg, 0.0));
  const LocalParameters lower = blend(points_[y.lower][l.lower], points_[y.lower][l.lower + 1], l.weight);
  const LocalParameters upper = blend(points_[y.lower + 1][l.lower], points_[y.lower + 1][l.lower + 1], l.weight);
  LocalParameters local = blend(lower, upper, y.weight);
  if (moving_mass_kg_) local.mass_kg = *moving_mass_kg_ + std::max(load_kg, 0.0);
  return local;
}

}  // namespace hsa::sim
