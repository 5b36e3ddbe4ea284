// The small-signal plant of rigs other than the paper's: each parameter a configuration can set
// moves b0, b1 and k01 the way the linearized equations say (Puglisi et al. 2015, eqs 5–7).
//
// With the rod still at a hold point, and the valve's pressure-flow slope neglected (it is the
// null leakage's alone, a fraction of a L/min), eqs 5–7 give
//   k_h = Ap²·β·(1/V_A + α²/V_B),   b0 = k_h/m,   b1 = σ_eff/m,
//   k01 = c·(√(Ps − PA)/V_A + α·√PB/V_B) / (Ap·(1/V_A + α²/V_B)),
// with the chamber pressures PA, PB of the equilibrium. The tests compare the ratio of a variant's
// coefficients to the base rig's with the ratio of these expressions.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/cylinder.hpp"
#include "sim/small_signal.hpp"

namespace hsa::sim {
namespace {

constexpr double kPosition = 0.150;
constexpr double kLoad = 3.0;

struct HandPlant {
  double b0, b1, k01;
};

HandPlant hand_plant(const Cylinder& cylinder, const SmallSignalPlant& linearized) {
  const CylinderGeometry& g = cylinder.parameters().geometry;
  const LocalParameters local = cylinder.local_parameters(kPosition, kLoad);
  const double area = g.piston_area();
  const double alpha = g.area_ratio();
  const double va = g.volume_a(kPosition);
  const double vb = g.volume_b(kPosition);
  const double stiffness = area * area * local.bulk_modulus_pa * (1.0 / va + alpha * alpha / vb);
  const double ps = cylinder.supply().supply_pressure_pa;
  const CylinderState& eq = linearized.equilibrium;
  const double k01 = local.flow_coefficient *
                     (std::sqrt(ps - eq.pressure_a_pa) / va + alpha * std::sqrt(eq.pressure_b_pa) / vb) /
                     (area * (1.0 / va + alpha * alpha / vb));
  return {stiffness / local.mass_kg, local.damping_n_s_per_m / local.mass_kg, k01 * 1e3};
}

// Relative agreement of the linearized ratio with the hand-derived one.
constexpr double kRatioAgreement = 1e-3;

// The hand model drops the valve's pressure-flow slope (the flow-pressure coefficient at the hold
// opening, set by the null leakage). With the default 0.3 L/min it is not negligible: the chambers'
// pressure relaxation β·Kc/V adds to σ/m in b1 and couples into b0 and k01, so a variant that
// changes β, V or Ps moves b1 by up to 4 % and b0, k01 by about 0.5 % beyond the expressions above.
// These rigs leak next to nothing, so the expressions hold to kRatioAgreement.
CylinderParameters tight() {
  CylinderParameters p;
  p.null_leakage_m3_per_s = 1e-9;
  return p;
}

void expect_ratios(const CylinderParameters& base_parameters, const CylinderParameters& variant_parameters,
                   const SupplyParameters& supply = {}) {
  const Cylinder base(base_parameters, supply);
  const Cylinder variant(variant_parameters, supply);
  const SmallSignalPlant b = linearize(base, kPosition, kLoad);
  const SmallSignalPlant v = linearize(variant, kPosition, kLoad);
  const HandPlant hb = hand_plant(base, b);
  const HandPlant hv = hand_plant(variant, v);
  EXPECT_NEAR((v.b0 / b.b0) / (hv.b0 / hb.b0), 1.0, kRatioAgreement) << v.b0 / b.b0;
  EXPECT_NEAR((v.b1 / b.b1) / (hv.b1 / hb.b1), 1.0, kRatioAgreement) << v.b1 / b.b1;
  EXPECT_NEAR((v.k01_mm_per_s / b.k01_mm_per_s) / (hv.k01 / hb.k01), 1.0, kRatioAgreement)
      << v.k01_mm_per_s / b.k01_mm_per_s;
}

// A 32 mm bore instead of 25 and oil half as stiff again: the hydraulic spring grows with the
// area (the volumes grow with it too, so k_h ∝ Ap·β at a fixed rod) and with β, so b0 rises by
// about (32/25)²·1.5 ≈ 2.0 less what the thinner annulus costs; the same valve moves a wider
// piston slower, k01 ∝ 1/Ap; the mass and damping are the paper's, so b1 does not move.
TEST(SmallSignal, LargerBoreAndStifferOilRaiseB0AndLowerK01AsTheEquationsSay) {
  CylinderParameters base = tight();
  base.dynamics.bulk_modulus_pa = 1.0e9;
  CylinderParameters variant = base;
  variant.geometry.bore_m = 0.032;
  variant.dynamics.bulk_modulus_pa = 1.5e9;
  expect_ratios(base, variant);

  const SmallSignalPlant b = linearize(Cylinder(base, {}), kPosition, kLoad);
  const SmallSignalPlant v = linearize(Cylinder(variant, {}), kPosition, kLoad);
  EXPECT_GT(v.b0 / b.b0, 1.8);
  EXPECT_LT(v.k01_mm_per_s / b.k01_mm_per_s, 0.7);
  EXPECT_NEAR(v.b1 / b.b1, 1.0, kRatioAgreement);
}

// Twice the moving mass and a valve of half the flow coefficient: b0 and b1 halve (k_h and σ_eff
// stay). k01 halves with c, and loses a little more because the heavier load holds chamber A
// nearer supply, leaving less pressure drop across the P→A land: 0.489, as the expression gives.
TEST(SmallSignal, HeavierMassAndSmallerValveHalveTheGainsAsTheEquationsSay) {
  const double c = Cylinder(CylinderParameters{}, {}).local_parameters(kPosition, kLoad).flow_coefficient;
  CylinderParameters base = tight();
  base.dynamics.moving_mass_kg = 2.0;
  base.dynamics.viscous_damping_n_s_per_m = 300.0;
  CylinderParameters variant = base;
  variant.dynamics.moving_mass_kg = 2.0 * (2.0 + kLoad) - kLoad;  // twice the total mass
  variant.dynamics.flow_coefficient = 0.5 * c;
  expect_ratios(base, variant);

  const SmallSignalPlant b = linearize(Cylinder(base, {}), kPosition, kLoad);
  const SmallSignalPlant v = linearize(Cylinder(variant, {}), kPosition, kLoad);
  EXPECT_NEAR(v.b0 / b.b0, 0.5, 0.5 * kRatioAgreement);
  EXPECT_NEAR(v.b1 / b.b1, 0.5, 0.5 * kRatioAgreement);
  EXPECT_LT(v.k01_mm_per_s / b.k01_mm_per_s, 0.5);
  EXPECT_GT(v.k01_mm_per_s / b.k01_mm_per_s, 0.48);
}

// A lower supply pressure leaves the hydraulic spring (β, volumes) and slows the valve's flow,
// k01 ∝ √Δp at the hold point.
TEST(SmallSignal, LowerSupplyPressureLowersK01AsTheOrificeEquationSays) {
  const CylinderParameters parameters = tight();
  SupplyParameters low;
  low.supply_pressure_pa = 12.5e5;
  const Cylinder base(parameters, {});
  const Cylinder variant(parameters, low);
  const SmallSignalPlant b = linearize(base, kPosition, kLoad);
  const SmallSignalPlant v = linearize(variant, kPosition, kLoad);
  const HandPlant hb = hand_plant(base, b);
  const HandPlant hv = hand_plant(variant, v);
  EXPECT_NEAR((v.k01_mm_per_s / b.k01_mm_per_s) / (hv.k01 / hb.k01), 1.0, kRatioAgreement);
  EXPECT_LT(v.k01_mm_per_s, 0.8 * b.k01_mm_per_s);
  EXPECT_NEAR(v.b0 / b.b0, 1.0, kRatioAgreement);
}

}  // namespace
}  // namespace hsa::sim
