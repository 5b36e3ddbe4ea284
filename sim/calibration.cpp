#include "sim/calibration.hpp"

#include <algorithm>
#include <cmath>

#include "sim/paper_tables.hpp"
#include "sim/small_signal.hpp"

namespace hsa::sim {

std::vector<CalibrationRow> calibration_table(const CylinderParameters& parameters,
                                              const SupplyParameters& supply) {
  const Cylinder cylinder(parameters, supply);
  std::vector<CalibrationRow> rows;
  rows.reserve(paper::kWorkingPositions * paper::kLoads);
  for (const paper::TransferRow& row : paper::kTableA3) {
    for (std::size_t j = 0; j < paper::kLoads; ++j) {
      const double y = row.position_mm * 1e-3;
      const double load = paper::kLoadKg[j];
      const SmallSignalPlant plant = linearize(cylinder, y, load);
      const paper::Transfer& t = row.by_load[j];
      rows.push_back({y, load, plant.b0, plant.b1, plant.k01_mm_per_s, t.b0, t.b1, t.k01});
    }
  }
  return rows;
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
