#pragma once

namespace hsa::control {

// What the valve loop needs of the proportional valve (Canuto et al. (2014) section 2, eqs 1–7),
// as control/identification/valve_fit.hpp identifies it (identified_valve() there fills it from a
// fit); SI. The laws and the model predictor that use it never read the simulator's constants.
struct IdentifiedValve {
  double gain_m_per_a = 0.0;          // g = K_f/K
  double rest_position_m = 0.0;       // X_min
  double natural_frequency_hz = 0.0;  // f0
  double damping_ratio = 0.0;         // ζ
  double magnetic_lag_s = 0.0;        // τa
  double width_a = 0.0;               // w
  double delay_s = 0.0;               // regulator τ + current-to-LVDT δ
  double current_max_a = 0.0;         // I_max

  bool operator==(const IdentifiedValve&) const = default;
};

}  // namespace hsa::control
