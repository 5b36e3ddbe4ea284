// The power unit of the paper's rig (section 3.3): a gear pump set to about 5 L/min at 25 bar
// supply, with tank at 0 bar gauge.
//
// A fixed-displacement pump with a relief valve holds the supply pressure while the valve draws
// less than the pump delivers; past that the supply pressure sags until the metering orifice passes
// exactly the pump's flow. That sag is the velocity limit of the paper's Fig. 3 (≈ 0.17 m/s
// extending), so it is modelled algebraically in supply_pressure_for() rather than as another state.
#pragma once

namespace hsa::sim {

struct SupplyParameters {
  double supply_pressure_pa = 25e5;         // relief setting
  double pump_flow_m3_per_s = 5.0 / 60000;  // 5 L/min

  friend bool operator==(const SupplyParameters&, const SupplyParameters&) = default;
};

// The pressure at the valve's P port when an orifice of conductance `orifice_conductance`
// (Q = c·√Δp) draws from it into a chamber at `port_pressure_pa`.
[[nodiscard]] inline double supply_pressure_for(const SupplyParameters& supply, double orifice_conductance,
                                                double port_pressure_pa) {
  const double ps = supply.supply_pressure_pa;
  if (orifice_conductance <= 0.0 || port_pressure_pa >= ps) return ps;
  // Δp at which the orifice passes exactly the pump flow.
  const double q_over_c = supply.pump_flow_m3_per_s / orifice_conductance;
  const double sagged = port_pressure_pa + q_over_c * q_over_c;
  return sagged < ps ? sagged : ps;
}

}  // namespace hsa::sim
