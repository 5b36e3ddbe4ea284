#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace hsa::control {

// A model-predictive valve law with preview, on the valve identified after Canuto et al. (2014)
// section 2 (eqs 1–3, 6, 7; control/identification/valve_model.hpp). docs/valve-loop.md, "the
// predictive law", has why and what it measured; valve_predictive_design.hpp builds its matrices
// and chooses its settings offline. This class only runs them.
//
// The law reads the reference P samples ahead of the loop: the target of the LVDT reading y(i) is
// r(i − P), so the delay eq 9 measures is P samples, and a corner of the reference is known P
// samples before the reading must turn. Its model, discretised exactly at the period T
// (zero-order hold), has the state
//
//   z = [c, x, ẋ, y, d, 1, I(i−1) … I(i−D)]
//
// c the force current behind the magnetic lag τa, x and ẋ the spool, y the reading behind the
// LVDT's first-order filter, d an input disturbance in amperes (what the model misses: a slow
// offset), 1 for the affine terms (X_min, the play's mean w/2 below the current), and the commands
// still in the regulator and current-to-LVDT delay of D samples. The identified dry friction
// enters as a known force −K·s_f·φ(i), φ(i) = tanh(ṙ_t(i)/v_d) with ṙ_t the target's slope: the
// spool moves with the target, so the friction's sign is known P samples ahead too.
//
// Each sample it
// 1. corrects z with the reading through a steady-state Kalman gain (the disturbance a random
//    walk, the reading's noise the LVDT's), with a faster walk's gain while the target is held;
// 2. minimises, over the next H commands within [lo, hi],
//      Σ_{j<H} (y(i+j) − r(i+j−P))² + ρ·(I(i+j) − I(i+j−1))²  +  the LQ cost-to-go at i + H,
//    the reference held after the last one known; a quadratic program in the H commands, whose
//    Hessian and linear map the design computed (box constraints, solved by an active-set method
//    warm-started from the last sample's active set; see solve_qp() for its two ways of solving a
//    step, whose cost follows the smaller of the bound and the free commands);
// 3. applies the first command, with the dither added, and predicts z one sample on.
//
// Everything is sized in the constructor; update() neither allocates nor throws. A QP that has not
// settled in `max_qp_iterations` steps, or within kQpWorkBudget multiply-adds, is cut there and its
// first command clamped to the box.
struct ValvePredictiveParams {
  bool enabled = false;
  double period_s = 1e-4;
  int delay_samples = 0;     // D
  int preview_samples = 0;   // P
  int horizon_samples = 0;   // H
  double lower_a = 0.0;      // the commands' box, before the dither
  double upper_a = 0.0;
  double current_max_a = 0.0;  // I_max: the dithered output is clamped to [0, I_max]
  double dither_amplitude_a = 0.0;
  int dither_half_period_samples = 0;  // 0: no dither
  double direction_velocity_m_s = 2e-3;  // v_d of φ
  // W: each reference is the mean of the last W given (a cascade: its cylinder loop's period in
  // base ticks, over which the opening is held). 1: the reference as given.
  int reference_window_samples = 1;
  // For the state at rest: x = X_min + g·c, and the commands that hold c, c + w/2.
  double gain_m_per_a = 0.0;
  double rest_position_m = 0.0;
  double mean_play_a = 0.0;
  // Row-major; n_p = 6 + D plant states, n = n_p + 2·(P + 1) with the reference and φ registers.
  std::vector<double> transition;    // n_p × n_p
  std::vector<double> input;         // n_p: the command
  std::vector<double> friction;      // n_p: φ
  std::vector<double> kalman_gain;   // n_p
  // n_p, or empty: the gain while the target is held, moving by at most held_band_m over the
  // preview (a faster disturbance estimate).
  std::vector<double> held_kalman_gain;
  double held_band_m = 0.0;
  std::vector<double> qp_hessian;    // H × H, in µm² per A² (the cost's scale)
  std::vector<double> qp_linear;     // H × n
  int max_qp_iterations = 0;

  bool operator==(const ValvePredictiveParams&) const = default;
};

// The plant state's fixed part, in the order above; the delay line's commands follow it.
enum ValvePredictiveState { kForce = 0, kPosition = 1, kVelocity = 2, kReading = 3, kDisturbance = 4, kOne = 5 };
inline constexpr int kValvePredictiveFixedStates = 6;  // c, x, ẋ, y, d, 1

class ValvePredictiveLaw {
 public:
  // The QP's multiply-adds a sample may take (solve_qp()): about 15 µs on the 2 GHz x86 machine
  // the benchmarks ran on (bench_valve_loop), within the 100 µs base tick with hsad's own work.
  static constexpr long kQpWorkBudget = 40000;
  // Missed samples the model catches up on at most (StatePredictor's bound).
  static constexpr std::uint64_t kMaxCatchUp = 100;
  // The reference's window at most (W sums per sample).
  static constexpr int kMaxReferenceWindow = 1000;

  // Throws std::invalid_argument for a law that is not enabled or whose sizes do not agree.
  explicit ValvePredictiveLaw(const ValvePredictiveParams& params);

  // At rest at the reading, on a reference held at `reference_m`.
  void reset(double measured_m, double reference_m) noexcept;

  // One sample: the reference r(i) and the LVDT reading y(i); returns the current command.
  // `elapsed` (>= 1; 0 counts as 1): samples T since the last update. The m − 1 missed ones held
  // the last command, and the model runs them open loop (at most kMaxCatchUp of them).
  double update(double reference_m, double measured_m, std::uint64_t elapsed = 1) noexcept;

  // The QP's first command sits at the box's edge: the loop asks for more than the current the
  // dither leaves (what an axis's current_saturated fault judges).
  [[nodiscard]] bool saturated() const noexcept { return saturated_; }

  // The last sample's QP: its steps, its commands at a bound of the box, its multiply-adds as
  // solve_qp() counts them, whether it ended at the optimum (rather than at the work budget or
  // the iteration limit), its H commands before they were clamped to the box, and the state
  // z, ξ, φ it was solved for (the QP's x0).
  [[nodiscard]] int last_qp_iterations() const noexcept { return qp_iterations_; }
  [[nodiscard]] int last_active_commands() const noexcept { return active_count_; }
  [[nodiscard]] long last_qp_work() const noexcept { return qp_work_; }
  [[nodiscard]] bool last_qp_complete() const noexcept { return qp_complete_; }
  [[nodiscard]] std::span<const double> last_commands() const noexcept { return u_; }
  [[nodiscard]] std::span<const double> last_qp_state() const noexcept { return x0_; }

 private:
  void advance_reference(double reference_m) noexcept;
  void predict(double command_a) noexcept;  // z one sample on, the dither's phase too
  double solve_qp() noexcept;
  void solve_free() noexcept;
  void solve_bound(int k) noexcept;
  void bind(int i, int side) noexcept;  // side: −1 at lo, +1 at hi, 0 free
  [[nodiscard]] double hessian(int r, int c) const noexcept { return p_.qp_hessian[static_cast<std::size_t>(r * h_ + c)]; }
  [[nodiscard]] double inverse(int r, int c) const noexcept { return inverse_[static_cast<std::size_t>(r * h_ + c)]; }
  [[nodiscard]] double bound_of(int i) const noexcept {
    return active_[static_cast<std::size_t>(i)] < 0 ? p_.lower_a : p_.upper_a;
  }

  ValvePredictiveParams p_;
  int np_ = 0, n_ = 0, h_ = 0, P_ = 0;
  bool started_ = false;
  std::vector<double> window_;  // the last W references given
  std::size_t window_head_ = 0;
  double held_a_ = 0.0;  // the last command, before the dither
  bool saturated_ = false;
  std::uint32_t dither_phase_ = 0;
  int qp_iterations_ = 0;
  int active_count_ = 0;
  long qp_work_ = 0;
  bool qp_complete_ = false;
  bool gradient_ready_ = false;  // gradient_ holds c + H·b̃ for this sample (solve_free())
  std::vector<double> inverse_;  // H⁻¹, H × H
  std::vector<double> unconstrained_;  // −H⁻¹·F, H × n: the commands with no bound active
  std::vector<double> z_, znext_, x0_, gradient_, u_, u_free_, chol_, rhs_, multiplier_;
  std::vector<int> active_, free_, bound_;  // active_: −1 at lo, +1 at hi, 0 free; free_, bound_: their indices
};

}  // namespace hsa::control
