// The plant identified at one working point, in the form of Puglisi et al. (2015), eqs 38/41,
// with what the run showed beyond it (hydraulic_fit.hpp says why):
//
//   y''' + b1·y'' + b0·y' = b0·(k01·xv⁺(t − τ) + k01⁻·xv⁻(t − τ) + v₀)       y in mm
//
// plant() is the paper's single-gain form with k01 (the extending gain, as Table A3's).
#pragma once

#include "control/identification/estimate.hpp"
#include "control/plant_table.hpp"

namespace hsa::control::identification {

struct PlantEstimate {
  Estimate b0;             // 1/s²
  Estimate b1;             // 1/s
  Estimate k01;            // mm/s per unit opening, extending
  Estimate k01_retracting; // mm/s per unit opening, retracting
  double delay_s = 0.0;    // τ
  double leak_speed_mm_per_s = 0.0;  // v₀

  [[nodiscard]] CylinderPlant plant() const { return {k01.value * b0.value, b1.value, b0.value}; }
};

}  // namespace hsa::control::identification
