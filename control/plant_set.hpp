// A set of plants identified at several working points of one axis, with the nominal one and the
// axis's capability: what `hsa-analyze identify --set` finds and writes, and what hsa-analyze loop
// and hsad's robustness checks read (plant_set/plant_set_file.hpp reads and writes the file;
// docs/plant-set.md describes it). Table A3 of Puglisi et al. (2015) is such a set, with integer
// working points (plant_table.hpp); an identified set's working points are measured, not chosen,
// so they are real numbers here. Units are SI; the paper's mm come in only through plant().
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "control/identification/axis_capability.hpp"
#include "control/identification/estimate.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {

struct PlantSetEntry {
  std::string name;          // the run it came from and its load, "run-3kg.csv@3kg"
  double position_m = 0.0;   // the run's mean setpoint
  double load_kg = 0.0;      // the external load, as the operator named it
  identification::Estimate b0_per_s2, b1_per_s;
  identification::Estimate k01_m_s;              // extending speed gain, m/s per unit opening
  identification::Estimate k01_retracting_m_s;   // retracting, m/s per unit opening (positive)
  double delay_s = 0.0;
  double kp_per_m = 0.0;     // the run's P gain
  double fit_index = 0.0;    // eq 39 on its own run
  double nominal_score = 0.0;  // Σ over the set's runs of its fit (eq 49)

  // Eq 41 in the paper's units: gain k01·b0 in mm·s⁻³.
  [[nodiscard]] CylinderPlant plant() const { return {k01_m_s.value * 1e3 * b0_per_s2.value, b1_per_s.value,
                                                      b0_per_s2.value}; }
};

struct PlantSet {
  static constexpr int kFormatVersion = 1;
  std::vector<PlantSetEntry> plants;
  std::size_t nominal = 0;  // index into plants, eq 49
  identification::AxisCapability capability;
  // The nameplate figures the capability was computed with.
  double supply_pressure_pa = 0.0;
  double pump_flow_m3_per_s = 0.0;
  double piston_area_m2 = 0.0;
  double area_ratio = 0.0;
};

}  // namespace hsa::control
