#pragma once

// Offline choice of the valve law's velocity and acceleration feedback (K_v, K_a of Canuto et al.
// (2014) eq 31) on the identified valve, behind the model predictor (valve_model_predictor.hpp).
//
// The preset's K_v and K_a were tuned on the simulator behind the paper's predictor, whose v and a
// carry the LVDT's noise: they are as much damping as that noise allowed. Behind the model
// predictor the estimates are cleaner and more damping pays (docs/valve-loop.md), but how much is
// decided by the dead band under the dither, which the linear loop G (valve_learning_design.hpp)
// leaves out: it predicts about the same residual for every choice. So the choice is made on a
// simulation of the identified valve itself:
//
//   the current δ late, the magnetic play of width w (eq 6, its edges as identified, the law's
//   dither moving it), the lag τa to the force current, the spring–mass of gain g, mode f0 and
//   damping ζ (eqs 1–3), integrated in four substeps per sample; the reading is its position plus
//   white noise of the LVDT's rms (a datasheet figure: the fit does not give it)
//
// under the law (K_v, K_a scaled by factors from a grid, K_rv and K_ra moved with them so that
// the model-inverse feed-forward stays the identified one) and the model predictor, on the 70 %
// triangle at 10 Hz: 2 periods to settle, 4 scored, eq 9's residual against the best pure delay
// (0.01 ms grid). The pair with the smallest peak residual is chosen.
//
// Nothing here knows the simulator: friction, the regulator's error and the LVDT's filter are
// not in the design model, and the choice is then measured on the simulated valves.

#include <cstdint>
#include <vector>

#include "control/identified_valve.hpp"
#include "control/valve_law.hpp"

namespace hsa::control {

struct ValveFeedbackDesignSettings {
  double lvdt_noise_m = 1e-6;  // rms of the position reading's white noise
  std::vector<double> velocity_factors{1.0, 1.5, 2.0, 2.5, 3.0};
  std::vector<double> acceleration_factors{1.0, 1.5, 2.0};
  std::uint64_t seed = 1;  // the noise sequence: the design is deterministic
};

struct ValveFeedbackDesign {
  double velocity_factor = 1.0;
  double acceleration_factor = 1.0;
  double peak_m = 0.0;    // the chosen pair's peak residual on the design model
  double preset_peak_m = 0.0;  // the factors (1, 1) on the same model
};

// `law` with K_v and K_a scaled, K_rv and K_ra moved by the same amounts.
ValveLawParams with_feedback_factors(ValveLawParams law, double velocity_factor, double acceleration_factor);

// The factors for `law` (a model-inverse law behind the model predictor, whose model is `valve`).
// Throws std::invalid_argument for an empty or non-positive factor list, a noise not >= 0, or a
// law without the model predictor.
ValveFeedbackDesign design_valve_feedback(const IdentifiedValve& valve, const ValveLawParams& law,
                                          const ValveFeedbackDesignSettings& settings = {});

}  // namespace hsa::control
