// The rig's small-signal response from valve opening to rod position at a working point, computed
// numerically from the same equations the simulator integrates, in the form of the paper's
// identified plants (eq 38, Table A3):
//
//   Y(s)/X(s) = k01·b0 / (s·(s² + b1·s + b0)),   Y in mm.
//
// Method: find the hold equilibrium (rod still, valve at the opening that balances the null
// leakage under the load); take the Jacobian of the smooth dynamics (dry friction off, as the
// paper's eq 7 linearizes it) over (velocity, PA, PB) by central differences, and the input column
// by a one-sided difference on the extending side of the opening, where the metering lands are
// the ones the calibration used. b0 and b1 come from the complex pole pair, k01 from the DC gain
// from opening to velocity. The third pole is the slow mode of the null leakage.
#pragma once

#include <array>
#include <complex>

#include "sim/cylinder.hpp"

namespace hsa::sim {

struct SmallSignalPlant {
  double b0 = 0.0;                // 1/s²
  double b1 = 0.0;                // 1/s
  double k01_mm_per_s = 0.0;      // rod speed per unit opening, mm/s
  double hold_opening = 0.0;      // valve opening at the equilibrium
  CylinderState equilibrium{};
  std::array<std::complex<double>, 3> poles{};  // of the velocity dynamics
};

[[nodiscard]] SmallSignalPlant linearize(const Cylinder& cylinder, double position_m, double load_kg);

}  // namespace hsa::sim
