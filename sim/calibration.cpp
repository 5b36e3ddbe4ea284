#include "sim/calibration.hpp"

#include <algorithm>
#include <cmath>

#include "sim/small_signal.hpp"

namespace hsa::sim {

CalibrationRow calibration_row(const Cylinder& cylinder, double position_m, double load_kg, double b0_table,
                               double b1_table, double k01_table) {
  const SmallSignalPlant plant = linearize(cylinder, position_m, load_kg);
  return {position_m, load_kg, plant.b0, plant.b1, plant.k01_mm_per_s, b0_table, b1_table, k01_table};
}

CalibrationSummary worst_deviation(const std::vector<CalibrationRow>& rows) {
  CalibrationSummary worst{0.0, 0.0, 0.0};
  for (const CalibrationRow& r : rows) {
    worst.b0 = std::max(worst.b0, std::abs(r.b0_deviation()));
    worst.b1 = std::max(worst.b1, std::abs(r.b1_deviation()));
    worst.k01 = std::max(worst.k01, std::abs(r.k01_deviation()));
  }
  return worst;
}

}  // namespace hsa::sim
