// The calibration check of the simulated rig: its small-signal plant (small_signal.hpp) at each
// of the paper's 33 working points, beside the identified plant of Table A3. The rig is calibrated
// from Tables A1 and A2 (identified_parameters.hpp), so Table A3 is an independent check of both
// the calibration and the nonlinear model's equations.
#pragma once

#include <vector>

#include "sim/cylinder.hpp"

namespace hsa::sim {

struct CalibrationRow {
  double position_m;
  double load_kg;
  double b0, b1, k01;                    // the model's, k01 in mm/s
  double b0_table, b1_table, k01_table;  // Table A3

  [[nodiscard]] double b0_deviation() const { return b0 / b0_table - 1.0; }
  [[nodiscard]] double b1_deviation() const { return b1 / b1_table - 1.0; }
  [[nodiscard]] double k01_deviation() const { return k01 / k01_table - 1.0; }
};

struct CalibrationSummary {
  double b0, b1, k01;  // worst absolute relative deviation
};

[[nodiscard]] std::vector<CalibrationRow> calibration_table(const CylinderParameters& cylinder,
                                                            const SupplyParameters& supply);
[[nodiscard]] CalibrationSummary worst_deviation(const std::vector<CalibrationRow>& rows);

}  // namespace hsa::sim
