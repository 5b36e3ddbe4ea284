// The first step of the valve's identification (valve_fit.hpp explains the method): a start for
// the output-error fit that needs no guess, by linear least squares on the equation error of
// Canuto et al. (2014) eqs 2 and 6 with the LVDT of eq 7, friction left out:
//
//   a3·y⁽³⁾ + a2·ÿ + a1·ẏ + y = g·S·p(t − d·T) + X_min,     S(s) = 1/(τs·s + 1),
//   a3 = τa/ω0²,  a2 = (1 + 2ζω0τa)/ω0²,  a1 = 2ζ/ω0 + τa,
//
// p the play of width w on the measured current. Every signal goes through the state-variable
// filter F(s) = λ⁴/(s + λ)⁴ (Young 1981), whose states are the filtered signal and its first three
// derivatives exactly; y is sampled as the smooth signal it is (first-order hold), p as the held
// one it is (zero-order hold, sampled_lti.hpp). For each w of a grid the least squares over
// (a3, a2, a1, g, X_min) is solved for every whole-sample delay d; the (w, d) of the smallest
// residual wins. τa is minus the inverse of the real root of a3·s³ + a2·s² + a1·s + 1, ω0 and ζ
// come from the other two.
#pragma once

#include <vector>

#include "control/identification/valve_model.hpp"

namespace hsa::control::identification {

struct EquationErrorOptions {
  double sensor_bandwidth_hz = 500.0;
  double max_width_a = 1.0;
  double width_step_a = 0.02;
  int max_delay_samples = 10;
  double filter_rad_s = 1500.0;
};

// use[k] false leaves sample k out (the spool near a stop). Returns the model with friction 0
// and no end stop; its delay is the whole samples d. Throws std::invalid_argument when the record is shorter than 20 filter time
// constants or no (w, d) gives a model with positive τa, ω0, ζ and g.
[[nodiscard]] ValveModel fit_valve_equation_error(const std::vector<double>& current_a,
                                                  const std::vector<double>& spool_m, const std::vector<bool>& use,
                                                  double period_s, const EquationErrorOptions& options);

}  // namespace hsa::control::identification
