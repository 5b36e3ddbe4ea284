#pragma once

#include <array>
#include <optional>

namespace hsa::control {

// Linear model of the cylinder from valve opening to rod position (Puglisi et al. 2015, eqs 38 and 41):
//
//   P(s) = Y(s)/Xv(s) = gain / (s³ + b1·s² + b0·s),   gain = k01·b0
//
// in the paper's units: Y in millimetres per unit of normalized valve opening Xv. Callers that
// work in SI convert at the boundary (loop_analysis.hpp does).
struct CylinderPlant {
  double gain = 0.0;  // mm·s⁻³ per unit opening
  double b1 = 0.0;    // s⁻¹
  double b0 = 0.0;    // s⁻²
};

// One row of Table A3 ("Parameter of the transfer functions") at one working point.
struct IdentifiedPlant {
  int position_mm = 0;
  int load_kg = 0;  // external load added to the rod
  double b0 = 0.0;
  double b1 = 0.0;
  double k01 = 0.0;  // mm/s: no-load rod speed at full opening

  [[nodiscard]] constexpr double position_m() const { return position_mm * 1e-3; }
  [[nodiscard]] constexpr CylinderPlant plant() const { return {k01 * b0, b1, b0}; }
};

// Table A3 of Puglisi et al. 2015, the 33 plants identified at 11 rod positions and 3 external
// loads, transcribed from the paper's appendix; its one copy in the repository. Ordered by
// position, then load. The simulator's calibration check (sim/calibration.hpp) is handed this
// table by its callers, so sim/ and control/ stay independent of each other.
inline constexpr std::array<IdentifiedPlant, 33> kTableA3{{
    // position_mm, load_kg, b0, b1, k01
    {10, 0, 13345, 128, 266},
    {10, 3, 11040, 110, 274},
    {10, 6, 9837, 101, 258},
    {30, 0, 12771, 122, 259},
    {30, 3, 10515, 106, 261},
    {30, 6, 9201, 98, 248},
    {60, 0, 12036, 116, 249},
    {60, 3, 9929, 102, 245},
    {60, 6, 8453, 94, 236},
    {90, 0, 11522, 111, 241},
    {90, 3, 9583, 99, 233},
    {90, 6, 7952, 92, 227},
    {120, 0, 11302, 108, 236},
    {120, 3, 9471, 98, 227},
    {120, 6, 7701, 90, 224},
    {150, 0, 11425, 106, 236},
    {150, 3, 9591, 97, 229},
    {150, 6, 7696, 90, 227},
    {180, 0, 11905, 107, 242},
    {180, 3, 9936, 98, 236},
    {180, 6, 7933, 91, 236},
    {210, 0, 12706, 108, 252},
    {210, 3, 10498, 100, 249},
    {210, 6, 8405, 93, 249},
    {240, 0, 13754, 112, 264},
    {240, 3, 11270, 104, 265},
    {240, 6, 9106, 96, 265},
    {270, 0, 14956, 117, 276},
    {270, 3, 12243, 108, 282},
    {270, 6, 10024, 100, 282},
    {290, 0, 15799, 121, 283},
    {290, 3, 13000, 112, 294},
    {290, 6, 10751, 103, 292},
}};

// The nominal plant P0 of eq 52, the identified plant at [6 kg, 120 mm] as the paper prints it
// (Table A3's rounded row gives gain 1.725e6, b1 90, b0 7701).
inline constexpr CylinderPlant kNominalPlant{1.722e6, 90.31, 7692.0};

// The Table A3 row at this working point, matched to 1e-6 m and 1e-6 kg; nullopt if none.
std::optional<IdentifiedPlant> find_identified_plant(double position_m, double load_kg);

}  // namespace hsa::control
