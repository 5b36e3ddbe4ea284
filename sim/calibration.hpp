// The calibration check of the simulated rig: its small-signal plant (small_signal.hpp) at each
// of the paper's 33 working points, beside the identified plant of Table A3 (Puglisi et al. 2015).
// The rig is calibrated from Tables A1 and A2 (identified_parameters.hpp), so Table A3 is an
// independent check of both the calibration and the nonlinear model's equations.
//
// The simulator holds no copy of Table A3: the caller hands in the identified plants (the one
// transcription is control::kTableA3, control/plant_table.hpp), as any range of rows with
// position_m(), load_kg, b0, b1 and k01 (mm/s). sim/ and control/ stay independent of each other.
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

// The model's plant at (position_m, load_kg), beside the identified b0, b1 and k01.
[[nodiscard]] CalibrationRow calibration_row(const Cylinder& cylinder, double position_m, double load_kg,
                                             double b0_table, double b1_table, double k01_table);

template <class IdentifiedRows>
[[nodiscard]] std::vector<CalibrationRow> calibration_table(const CylinderParameters& parameters,
                                                            const SupplyParameters& supply,
                                                            const IdentifiedRows& identified) {
  const Cylinder cylinder(parameters, supply);
  std::vector<CalibrationRow> rows;
  for (const auto& row : identified) {
    rows.push_back(calibration_row(cylinder, row.position_m(), row.load_kg, row.b0, row.b1, row.k01));
  }
  return rows;
}
[[nodiscard]] CalibrationSummary worst_deviation(const std::vector<CalibrationRow>& rows);

}  // namespace hsa::sim
