// The identified parameters of the paper's rig (Puglisi et al. 2015, Tables A1 and A2) at its 33
// working points: 11 rod positions × external loads of 0, 3 and 6 kg.
//
// The paper's three appendix tables describe one model: with b1 = −Kp + σ/m,
// b0 = (Ap·Kd − σ·Kp)/m and k01 = Ap·Kx/(m·b0) (eqs 19–21), Tables A1 and A2 reproduce Table A3
// within 1 % with a single constant Ap ≈ 127 in the paper's mixed units. The simulator is
// calibrated from A1 and A2; A3, transcribed once in control/plant_table.hpp, checks it
// (calibration.hpp).
#pragma once

#include <array>
#include <cstddef>

namespace hsa::sim::paper {

inline constexpr std::size_t kWorkingPositions = 11;
inline constexpr std::size_t kLoads = 3;
inline constexpr std::array<double, kLoads> kLoadKg = {0.0, 3.0, 6.0};

// The gravity of the paper's load force Fe = m·g (Table A1), m/s².
inline constexpr double kGravity = 9.81;

// The constant that maps Table A2's Kd and Kx to consistent units (eqs 19–21 above).
inline constexpr double kAreaConstant = 127.0;

struct Motion {
  double mass_kg;
  double viscous_n_s_per_m;  // σ; σ/m is in 1/s
  double external_force_n;   // Fe ≈ m·g
};

struct Sensitivity {
  double kx;  // flow sensitivity to valve opening (paper units)
  double kd;  // load-pressure sensitivity to rod speed (paper units)
  double kp;  // load-pressure self-coefficient [1/s], negative
};

struct MotionRow {
  double position_mm;
  std::array<Motion, kLoads> by_load;
};
struct SensitivityRow {
  double position_mm;
  std::array<Sensitivity, kLoads> by_load;
};

extern const std::array<MotionRow, kWorkingPositions> kTableA1;
extern const std::array<SensitivityRow, kWorkingPositions> kTableA2;

}  // namespace hsa::sim::paper
