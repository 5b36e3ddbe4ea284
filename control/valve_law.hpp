#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "control/identified_valve.hpp"
#include "control/state_predictor.hpp"
#include "control/tanh_through_exp.hpp"
#include "control/valve_time_optimal.hpp"
#include "control/valve_learning.hpp"
#include "control/valve_model_predictor.hpp"
#include "control/valve_predictive.hpp"

namespace hsa::control {

// Digital control law of the proportional valve's spool loop, Canuto et al. (2014) section 3.5, eq 31:
//
//   I(i)     = clamp(I0 + K_r·r(i) + K_i·s(i) + K_p(e(i)) - K_v·v(i) - K_a·a(i),  0, I_max)
//   s(i+1)   = s(i) + T·e(i)        (skipped while frozen, see anti-windup)
//   e(i)     = r(i) - x(i)
//
// r is the spool position reference, and x, v, a the position, velocity and acceleration of the
// state predictor (eqs 15–16). Everything is in SI: the paper's gains act on the predictor's
// per-sample increments and on error voltages, with b and K_s folding them into a current; here
// each gain maps its own physical quantity to amperes (K_r, K_p in A/m, K_i in A/(m·s),
// K_v in A/(m/s), K_a in A/(m/s²)), and s is the time integral of the error. The paper's gains
// convert as K_r = b·K_dr, K_i = b·K_di/T, K_v = b·K_dv·T, K_a = b·K_da·T², with b in A per
// unit of the bracket.
//
// Signs: the solenoid pulls the spool towards positive x against its return spring, so current
// and position rise together. The error terms (integral and K_p) therefore enter with a positive
// sign; eq 31 as printed writes them with a minus, which with this plant would be positive
// feedback (the paper's voltage conventions are not stated). Velocity and acceleration are
// damping and enter negatively, as the paper's derivative actions act on the measurement.
//
// K_p(e) is the smooth monotonic error function that replaces the analogue piecewise curve
// (Fig. 5) and inverts the solenoid's dead band (eqs 6, 32):
//
//   K_p(e) = k_p·e + ΔI·tanh(e / e_w)
//
// Its slope is k_p + ΔI/e_w at e = 0 and falls smoothly to k_p for |e| >> e_w; it is odd,
// strictly increasing, and adds at most ±ΔI. Choosing ΔI as half the dead band's width in current
// (about 0.15 A for the 0.3 A of Canuto et al. (2014)) lets a small error cross the dead band at once
// instead of waiting for the integrator, which is the delay of 20–30° the paper removes.
//
// I0 is the bias current that holds the spool at hydraulic zero: with r = x = v = a = 0 and an
// empty integrator the law outputs exactly I0 (plus the dither, when it is on).
//
// Dither (not in Canuto et al. (2014); standard in proportional-valve amplifiers): a square wave ±A_d at f_d
// is added to the output. An amplitude above half the dead band's width keeps the magnetic play
// moving, so the mean force follows the mean current instead of sticking in the band. The
// 1.5 ms magnetic lag and the 50 Hz spool take most of it off before it reaches the spool.
//
// Skipped samples: update(..., elapsed) with elapsed = m > 1 means m − 1 samples were missed. The
// error of the last sample held over them (zero-order hold, the same assumption as the output it
// produced), so before this sample's output the integral catches up by (m − 1)·T·e(i−m) when
// that sample integrated; the dither's phase advances by m. With m = 1 nothing changes.
//
// Anti-windup on the clamp by conditional integration: the integrator holds while the unclamped
// current is above I_max with e > 0, or below 0 with e < 0.
//
// Model-inverse feed-forward of the reference (not in Canuto et al. (2014); off when f_r = 0). Eq 31
// inverts only the spring (K_r·r); the valve of eqs 2, 3 and 6 between current and position is
//   g·c = x + a1·ẋ + a2·ẍ + …,   a1 = 2ζ/ω0 + τa + δ,  a2 = (1 + 2ζω0τa)/ω0²   (c: force current)
//   a3 = τa/ω0²   (the jerk term, from the lag in series with the spool)
// so the current that makes x follow r adds (a1·ṙ + a2·r̈ + a3·r⃛)/g, and, for the measured-state
// damping K_v·v + K_a·a not to brake a spool that is on its reference, K_v·ṙ + K_a·r̈: eq 31's
// damping then acts on the state's deviation from the reference's. The reference's derivatives
// come from a critically damped third-order state-variable filter at f_r (ω_r = 2π·f_r):
//   r⃛_f = ω_r³·(r − r_f) − 3ω_r²·ṙ_f − 3ω_r·r̈_f,  r̈_f += T·r⃛_f,  ṙ_f += T·r̈_f,  r_f += T·ṙ_f
// which turns a step into a bounded move (the current limit clips what the valve cannot follow)
// and lags a ramp by 3/ω_r. With track_filtered_reference the error and K_r·r use r_f: the loop
// then follows the move the feed-forward drives, and the feedback only corrects the model's error. The magnetic dead band adds ±w/2 by the direction of
// motion (the play sits w below the current while rising, at it while falling; eq 6); its
// compensation ΔI_d·tanh(ṙ_f / v_d) is smooth through the reversal. With the dither above w/2 the
// play moves every half period anyway and ΔI_d should stay 0.
//
// Repetitive rejection (off when N_rep = 0): the residual of a periodic reference repeats every
// period N_rep·T, so a plug-in repetitive term adds the error one period ago, low-passed:
//   u_rep(i) = Q·(u_rep(i − N) + k_rep·e(i − N + L))
// with Q a first-order low-pass at f_Q and L samples of phase lead; its buffer is sized at
// construction (nothing allocates in update()).
// f_r·T at most: the reference filter's explicit update needs ω_r·T well below 1.
inline constexpr double kMaxReferenceFilterTimesPeriod = 0.05;

struct ValveLawParams {
  double period_s = 1e-4;          // T: the valve loop runs at 10 kHz
  double bias_current_a = 0.0;     // I0
  double max_current_a = 3.0;      // I_max
  double feedforward_a_per_m = 0.0;                 // K_r
  double integral_a_per_m_s = 0.0;                  // K_i
  double proportional_a_per_m = 0.0;                // k_p: slope of K_p(e) far from zero
  double dead_band_compensation_a = 0.0;            // ΔI
  double dead_band_error_m = 1e-6;                  // e_w: error over which ΔI is reached
  double velocity_a_per_m_s = 0.0;                  // K_v
  double acceleration_a_per_m_s2 = 0.0;             // K_a
  double dither_amplitude_a = 0.0;                  // A_d, 0 = off
  double dither_frequency_hz = 0.0;                 // f_d = 1/(2·n·T), n whole
  double reference_velocity_a_per_m_s = 0.0;        // K_rv = a1/g + K_v
  double reference_acceleration_a_per_m_s2 = 0.0;   // K_ra = a2/g + K_a
  double reference_jerk_a_per_m_s3 = 0.0;           // K_rj = a3/g
  double reference_filter_hz = 0.0;                 // f_r, 0 = no feed-forward of ṙ, r̈
  bool track_filtered_reference = false;            // e and K_r·r on r_f instead of r
  double direction_compensation_a = 0.0;            // ΔI_d, about w/2
  double direction_velocity_m_s = 5e-3;             // v_d: ṙ_f over which ΔI_d is reached
  int repetitive_period_samples = 0;                // N_rep, 0 = off
  double repetitive_gain = 0.0;                     // k_rep, A/m
  double repetitive_filter_hz = 0.0;                // f_Q
  int repetitive_lead_samples = 0;                  // L
  ValveTimeOptimalParams time_optimal;              // full-effort moves on a jump (valve_time_optimal.hpp)
  // Learning (off when N = 0; control/valve_learning_design.hpp): the reference r + u, u learned
  // from the last period's error against r(i − D) through the non-causal filters q and h.
  int learning_period_samples = 0;                  // N
  int learning_delay_samples = 0;                   // D
  std::vector<double> learning_filter;              // q_j, j = −M … M
  std::vector<double> learning_kernel;              // h_j, j = −M … M
  int learning_settle_periods = 0;                  // periods to learn before an experiment scores
  // The predictor the valve loop runs in front of this law (valve_model_predictor.hpp) when enabled,
  // instead of the paper's (state_predictor.hpp); the law itself reads only the predictor's output.
  ValveModelPredictorParams model_predictor;
  // The predictive law (valve_predictive.hpp) when enabled: it then decides the command from the
  // reference and the reading alone, in place of this law and its predictor.
  ValvePredictiveParams predictive;

  bool operator==(const ValveLawParams&) const = default;
};

// Gains for the simulated proportional valve of Canuto et al. (2014) (sim/proportional_valve with
// its default parameters), to be used with the Table 2 predictor (γ = {0.4, 0.4, 0.04, 0.04}) at
// T = 1e-4 s. See valve_law.cpp for how they were tuned. A real valve needs its own: these know the simulator's spring, force
// constant and dead band.
ValveLawParams simulated_proportional_valve_law();

// The steps of docs/valve-loop.md, each on top of the previous.
enum class ValveLawStep {
  spring_inverse,   // eq 31 with I0, K_r, I_max and the dither's amplitude from the identified g, X_min, w,
                    // I_max (the preset's feedback)
  feedforward,      // + a1·ṙ/g from the identified f0, ζ, τa, δ, on the reference itself
  model_inverse,    // instead: the loop tracks r_f, fed (a1·ṙ_f + a2·r̈_f + a3·r⃛_f)/g + K_v·ṙ_f + K_a·r̈_f
  model_predictor,  // model_inverse behind the predictor driven by the identified model (valve_model_predictor.hpp)
  damped,           // model_predictor with K_v, K_a chosen on the identified model (valve_feedback_design.hpp)
  repetitive,       // model_inverse + repetitive rejection of a reference of period repetitive_period_s
  time_optimal,     // model_inverse + full-effort moves on a jump of the reference (valve_time_optimal.hpp)
  learning,         // model_inverse + the learning law designed on the identified loop (valve_learning_design.hpp)
};

// The model predictor's settings for `valve` (ValveLawStep::model_predictor): its model is the
// identified valve, its γ Table 2's halved (valve_law.cpp says why).
ValveModelPredictorParams identified_model_predictor(const IdentifiedValve& valve);

// The preset's feedback gains (tuned on the simulator, see valve_law.cpp) with everything the
// model fixes taken from `valve`. Throws std::invalid_argument for a non-physical valve
// (g, f0, ζ, τa or I_max not > 0, w or the delay < 0) or a repetitive or learning step without a
// period.
ValveLawParams identified_valve_law(const IdentifiedValve& valve, ValveLawStep step,
                                    double repetitive_period_s = 0.0);

class ValveLaw {
 public:
  // Throws std::invalid_argument for a non-positive period, I_max or e_w, a bias outside
  // [0, I_max], negative gains, a dither amplitude outside [0, I_max/2], or a dither frequency
  // that is not 1/(2·n·T).
  explicit ValveLaw(const ValveLawParams& params);

  // Empties the integrator.
  void reset(double integral_m_s = 0.0) noexcept;

  // One sample: returns the solenoid current reference in [0, I_max].
  // `elapsed` (>= 1; 0 counts as 1): samples T since the last update.
  // Inline, so that a law without the optional stages, on consecutive samples, pays one test for
  // them all and goes to eq 31 alone (bench_control_tick).
  double update(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed = 1) noexcept {
    if (elapsed > 1 || has_stages_) [[unlikely]] return update_with_stages(reference_m, predicted, elapsed);
    return update_plain(reference_m, predicted);
  }

  // K_p(e) above, in amperes. Inline: with the library built position-independent, an out-of-line
  // member is a call on every sample even from this class's own file.
  [[nodiscard]] double error_function(double error_m) const noexcept {
    return params_.proportional_a_per_m * error_m +
           params_.dead_band_compensation_a * tanh_through_exp(error_m / params_.dead_band_error_m);
  }

  [[nodiscard]] double current() const { return current_; }
  [[nodiscard]] double error() const { return error_; }
  [[nodiscard]] double integral() const { return integral_; }
  // The last current sat at a limit: the linear law's demand clipped, or a time-optimal move
  // driving or braking at 0 or I_max (chosen, but at the limit all the same).
  [[nodiscard]] bool saturated() const { return saturated_; }
  [[nodiscard]] std::uint64_t saturation_count() const { return saturation_count_; }
  [[nodiscard]] const ValveLawParams& params() const { return params_; }
  [[nodiscard]] const ValveTimeOptimal& time_optimal() const { return time_optimal_; }

 private:
  // The sample without a time-optimal move, learning, reference filter or repetitive term, after
  // one period: eq 31 and the dither; and the sample with any of them, or after a gap.
  double update_plain(double reference_m, const PredictorOutput& predicted) noexcept;
  double update_with_stages(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed) noexcept;
  // Eq 31 from the error_ of `reference` on: the output, the saturation and the anti-windup.
  // Always inline: with K_p(e)'s exp inline in it, GCC stopped inlining it into update_plain(),
  // and the call cost a tenth of the tick (bench_control_tick: 12.4 against 11.3 ns).
  [[gnu::always_inline]] inline double close_loop(double reference, double feedforward, double repetitive_term,
                           const PredictorOutput& predicted, std::uint64_t elapsed) noexcept;
  // The square wave's next sample, its phase moved on by `elapsed`. Inline, as error_function().
  double dither(std::uint64_t elapsed) noexcept {
    if (dither_half_period_samples_ == 0) return 0.0;
    if (elapsed > 1) [[unlikely]] {
      const std::uint64_t cycle = 2ull * dither_half_period_samples_;
      dither_phase_ = static_cast<std::uint32_t>((dither_phase_ + (elapsed - 1) % cycle) % cycle);
    }
    const bool high = dither_phase_ < dither_half_period_samples_;
    if (++dither_phase_ == 2 * dither_half_period_samples_) dither_phase_ = 0;
    return high ? params_.dither_amplitude_a : -params_.dither_amplitude_a;
  }
  double reference_feedforward(double reference_m) noexcept;
  double repetitive(double error_m) noexcept;
  // valve_time_optimal.cpp: true while a move decides the current (current_ set).
  bool time_optimal_move(double reference_m, const PredictorOutput& predicted, std::uint64_t elapsed) noexcept;
  ValveLawParams params_;
  bool has_stages_ = false;  // a time-optimal move, learning, the reference filter or a repetitive term
  double integral_ = 0.0;
  double error_ = 0.0;
  double current_ = 0.0;
  bool saturated_ = false;
  bool integrated_ = false;  // the last sample's error went into the integral
  std::uint64_t saturation_count_ = 0;
  std::uint32_t dither_half_period_samples_ = 0;
  std::uint32_t dither_phase_ = 0;
  // Reference filter (f_r) and repetitive buffers; sized in the constructor.
  double ref_position_ = 0.0, ref_velocity_ = 0.0, ref_acceleration_ = 0.0;
  bool ref_started_ = false;
  std::vector<double> rep_error_, rep_output_;
  std::size_t rep_head_ = 0;
  double rep_filtered_ = 0.0;
  ValveTimeOptimal time_optimal_;
  ValveLearning learning_;
};

}  // namespace hsa::control
