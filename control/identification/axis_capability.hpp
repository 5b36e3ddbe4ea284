// What the axis can do per direction at a run's load, from the identified plant: the largest rod
// speed and acceleration the valve can give, and the limits a motion profile may ask for (a margin
// below them). Built on the orifice model behind Puglisi et al. (2015), eqs 8–21, with the
// quantities `identify` measures (identify_run.hpp) and two the run cannot show, from the power
// unit's nameplate: the supply pressure P_s and the pump flow Q_p.
//
// Speed. A closed-centre valve fully open to extend meters P→A and B→T; in steady motion the
// orifice law gives (with P_A − α·P_B = F/A_p the load pressure and ρ(x) = c·x/A_p):
//
//   v = ρ(x)·√((P_s − F/A_p)/(1 + α³))                 extending
//   u = ρ(x)·√((α·P_s + F/A_p)/(1 + α³))               retracting (the load's weight helps)
//
// linear in the opening x. So the identified speed gains k⁺ and k⁻ (the rod speed per unit
// opening at the run's hold point, F = F_e) are the full-opening speeds against the run's load,
// and the flow the valve passes at full opening is k±·A_p. Moving, the rod also needs σ·v and the
// seals' F_c, which take their share of the pressure:
//
//   v_max = k⁺·√((A_p·P_s − F_e − F_c − σ·v_max)/(A_p·P_s − F_e)),
//   u_max = k⁻·√((α·A_p·P_s + F_e − F_c − σ·u_max)/(α·A_p·P_s + F_e)),
//
// quadratics in the speed. The pump caps both: the fed chamber takes at most Q_p, so
// v_max ≤ Q_p/A_p and u_max ≤ Q_p/(α·A_p).
//
// Acceleration: the smaller of
// - the force the supply can put on the identified mass after the load and friction, the fed
//   chamber at P_s and the other at tank: (A_p·P_s − F_e − F_c)/m extending, (α·A_p·P_s + F_e −
//   F_c)/m retracting;
// - the rate the hydraulic mode lets the speed rise when the valve opens fully at once: the speed
//   follows the opening through b0/(s² + b1·s + b0) (eq 38 with y' for y), so the acceleration
//   peaks at v_max·max_t h(t), h that transfer function's impulse response
//   (ω_n·exp(−ζ·acos ζ/√(1 − ζ²)) for ζ < 1, ω_n = √b0, ζ = b1/(2ω_n)). Where the pump caps the
//   speed it caps only the fed chamber's inflow; the other chamber drains at the valve's rate,
//   and the two chambers' springs share the load pressure about equally in mid-stroke, so the
//   speed that drives the mode is then the mean of the valve's and the pump's.
// On the paper's rig the second is the smaller by an order of magnitude: the oil spring, not the
// supply's force, limits how fast the rod picks up speed.
//
// Margin: a profile should ask for at most `margin` (default 0.7) of each. The loop needs valve
// opening beyond the profile's feedforward to correct errors: at the paper's Kp = 0.085 per mm
// the remaining 30 % of opening corrects about 3.5 mm of following error at top speed before the
// valve saturates. It also covers the identified gains' uncertainty (a few per cent) and a supply
// that sags or a warmer, thinner oil.
#pragma once

#include <string>
#include <vector>

#include "control/identification/identify_run.hpp"

namespace hsa::control::identification {

// The power unit's nameplate and the margin.
struct SupplyRating {
  double supply_pressure_pa = 25e5;
  double pump_flow_m3_per_s = 5.0 / 60000;
  double margin = 0.7;  // (0, 1]
};

struct DirectionCapability {
  double max_speed_m_s = 0.0;
  double max_acceleration_m_s2 = 0.0;
  bool speed_pump_limited = false;          // Q_p, not the valve, set max_speed_m_s
  bool acceleration_force_limited = false;  // the supply's force, not the hydraulic mode
  double speed_limit_m_s = 0.0;             // margin·max
  double acceleration_limit_m_s2 = 0.0;
  std::string worst_run;                    // the run it came from in a set (the worst load)
  double load_kg = 0.0;                     // that run's load
};

struct AxisCapability {
  double margin = 0.0;
  DirectionCapability extend, retract;
};

// The capability at one run's load. Throws std::invalid_argument for a rating that is not
// positive, a margin outside (0, 1], or a supply too weak to move the identified load
// (A_p·P_s ≤ F_e + F_c).
[[nodiscard]] AxisCapability axis_capability(const Identification& id, double piston_area_m2, double area_ratio,
                                             const SupplyRating& rating);

// Per direction, the smallest speed and acceleration over several runs' capabilities: the worst
// load, found rather than assumed (retracting, the weight helps but a heavier rod's damping takes
// more of the pressure). `names` and `loads_kg` label them; on a tie the first run is named.
[[nodiscard]] AxisCapability worst_capability(const std::vector<AxisCapability>& each,
                                              const std::vector<std::string>& names,
                                              const std::vector<double>& loads_kg);

// max_t of the impulse response of b0/(s² + b1·s + b0), 1/s.
[[nodiscard]] double peak_impulse_response(double b0, double b1);

}  // namespace hsa::control::identification
