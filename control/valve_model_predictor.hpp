#pragma once

#include <array>
#include <cstdint>

#include "control/command_delay_line.hpp"
#include "control/identified_valve.hpp"
#include "control/state_predictor.hpp"

namespace hsa::control {

// The valve loop's state predictor of Canuto et al. (2014) section 3.3 (eqs 13–17,
// state_predictor.hpp) with the identified valve's acceleration as a known input.
//
// The paper's predictor knows nothing of the valve: the spool's acceleration is an unknown drift d
// plus noise, estimated from the measured position alone, so every bit of the spool's 50 Hz mode
// that the law sees in v and a is a difference of noisy LVDT samples. Through the law's velocity and
// acceleration feedback that noise moves the spool: on the simulated valve the 1 µm rms LVDT noise
// becomes about 5 µm rms of spool motion that differs from one reference period to the next
// (docs/valve-loop.md). Here the acceleration is split into what the identified model says and what
// it misses:
//
//   a(i)   = u(i) + d(i) + w_a(i)
//   u(i)   = ω0²·(X_min + g·c(i) − x̂(i)) − 2ζω0·v̂(i)                (eqs 2, 3, the spool)
//   c(i+1) = c(i) + (1 − e^{−T/τa})·(p(i) − c(i)),  p(i) = I(i − δ) − w/2  (eqs 1, 6)
//
// with I the current the law output, δ the identified regulator and current-to-LVDT delay in whole
// samples, and p the magnetic play at its mean: the law's dither, above w/2, moves the play every
// half period, so on average it sits w/2 below the current both ways (docs/valve-loop.md, the
// dead-band paragraph). Eq 15 is unchanged but for u entering the velocity row (in metres per
// sample², u·T²), and the output acceleration is u + d + l_a·(y_x − x) + m_a·q. For a model that is
// exact the estimation error obeys the paper's error dynamics (eigenvalues 1 − γ_k), so the
// predictor's gains follow eqs 18–21 as before, but d now follows only the model's error (a slow
// offset of X_min or g, friction, the play's ripple), and the predictor's bandwidth can be lowered
// without the lag the paper's predictor would add. x̂, v̂ in u are the predictor's own estimates, a
// feedback of ω0²T² ≈ 1e-3 and 2ζω0T ≈ 0.02 per sample on the error, small against γ.
//
// Nothing in update() or commanded() allocates or throws.
struct ValveModelPredictorParams {
  bool enabled = false;
  IdentifiedValve valve;                           // the model: g, X_min, f0, ζ, τa, w, δ
  std::array<double, 4> gamma = kTable2Gamma;      // the complementary eigenvalues of eqs 18–21

  bool operator==(const ValveModelPredictorParams&) const = default;
};

class ValveModelPredictor {
 public:
  static constexpr int kMaxDelaySamples = CommandDelayLine::kMaxSamples;

  // Throws std::invalid_argument for a non-positive period, a non-physical model (g, f0, ζ, τa not
  // > 0, w or δ < 0, δ beyond kMaxDelaySamples samples) or γ outside (0, 1].
  ValveModelPredictor(const ValveModelPredictorParams& params, double period_s);

  // At rest at the given position; the model starts on the first commanded().
  void reset(double position_m) noexcept;

  // One sample: y(i) from the state and the measurement, then the state advances to i + 1.
  PredictorOutput update(double measured_position_m) noexcept;

  // The current the law output this sample: the model's input, δ samples later.
  void commanded(double current_a) noexcept;

 private:
  ValveModelPredictorParams params_;
  PredictorGains gains_;
  double period_s_;
  double w0_;
  double lag_factor_;  // 1 − e^{−T/τa}
  // The state of eq 15, in metres per sample as the paper's: x, v (increment), d (drift), q.
  double x_ = 0.0, v_ = 0.0, d_ = 0.0, q_ = 0.0;
  double force_ = 0.0;
  bool started_ = false;
  CommandDelayLine delay_line_;  // the last δ commands
};

}  // namespace hsa::control
