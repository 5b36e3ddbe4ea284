#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace hsa::control {

// Fourth-order state predictor of the digital valve loop, Canuto et al. (2014) section 3.3, eqs 13–17.
//
// Driven only by the measured spool position y_x, it treats the spool acceleration as unknown: a
// drift d plus a noise w_a, with the drift driven by a noise w_d, both estimated from the model
// error e_m = y_x - x through a dynamic feedback state q (eq 17). With the state (x, v, d, q):
//
//   x(i+1) = A·x(i) + L·y_x(i)                                                         (eq 15)
//   y(i)   = C_m·x(i) + D_m·y_x(i),   y = (x, v, a)
//
//       | 1     1  0  0     |       | 0   |         | 1     0  0  0   |         | 0   |
//   A = | -l_a  1  1  m_a   |   L = | l_a |   C_m = | 0     1  0  0   |   D_m = | 0   |    (eq 16)
//       | -l_d  0  1  m_d   |       | l_d |         | -l_a  0  1  m_a |         | l_a |
//       | -1    0  0  1-β   |       | 1   |
//
// v is the position increment per sample and a the discrete-time acceleration (increment of the
// increment), both in metres as in the paper; update() returns them divided by T and T² so the
// valve law sees m/s and m/s².
//
// Gains (eqs 18–21): the eigenvalues of A are λ_k = 1 - γ_k for complementary eigenvalues
// γ_k ∈ (0, 1]. With ∏(γ + γ_k) = γ⁴ + c3·γ³ + c2·γ² + c1·γ + c0,
//   β = c3,   l_a = c2,   m_a = c1 - β·l_a - l_d,   m_d = c0 - β·l_d,
// for any l_d in C = [c1 - β·l_a, c0/β]. The transfer functions from y_x do not depend on l_d
// (Theorem 1), so l_d = 0 is the default.
struct PredictorCoefficients {
  double c3 = 0.0;
  double c2 = 0.0;
  double c1 = 0.0;
  double c0 = 0.0;
};

struct PredictorGains {
  double beta = 0.0;
  double l_a = 0.0;
  double l_d = 0.0;
  double m_a = 0.0;
  double m_d = 0.0;

  bool operator==(const PredictorGains&) const = default;
};

// Table 2 of Canuto et al. (2014).
inline constexpr std::array<double, 4> kTable2Gamma{0.4, 0.4, 0.04, 0.04};

// Coefficients of eq 18. Throws std::invalid_argument unless every γ_k is in (0, 1].
PredictorCoefficients predictor_coefficients(const std::array<double, 4>& gamma);

// Gains of eqs 19–21. Throws std::invalid_argument for γ outside (0, 1] or l_d outside C.
PredictorGains predictor_gains(const std::array<double, 4>& gamma, double l_d = 0.0);

// A and L of eq 16.
Eigen::Matrix4d predictor_state_matrix(const PredictorGains& gains);
Eigen::Vector4d predictor_input_vector(const PredictorGains& gains);

struct PredictorOutput {
  double position_m = 0.0;
  double velocity_m_s = 0.0;
  double acceleration_m_s2 = 0.0;
};

class StatePredictor {
 public:
  // Throws std::invalid_argument for a non-positive period.
  StatePredictor(const PredictorGains& gains, double period_s);

  // Starts at rest at the given position, so no transient follows a start away from zero.
  void reset(double position_m) noexcept;

  // One sample: outputs y(i) from the state x(i) and y_x(i), then advances to x(i+1).
  // `elapsed` = m > 1 (samples since the last update) first advances the state over the m − 1
  // missed samples with this measurement held (at most kMaxCatchUp of them, so the cost stays
  // bounded; a gap that long is a blind-time fault of the axis anyway). m = 1 is the plain step.
  static constexpr std::uint64_t kMaxCatchUp = 100;
  // The test of `elapsed` is inline, so that a caller on consecutive samples (a constant 1) does
  // not pay for it, nor step() for the registers the catch-up call needs (bench_control_tick).
  PredictorOutput update(double measured_position_m, std::uint64_t elapsed = 1) noexcept {
    if (elapsed > 1) [[unlikely]] catch_up(measured_position_m, elapsed);
    return step(measured_position_m);
  }

  [[nodiscard]] const Eigen::Vector4d& state() const { return x_; }
  [[nodiscard]] const PredictorGains& gains() const { return gains_; }
  [[nodiscard]] double period_s() const { return period_s_; }

 private:
  void catch_up(double measured_position_m, std::uint64_t elapsed) noexcept;  // the m − 1 missed samples
  PredictorOutput step(double measured_position_m) noexcept;                 // eq 15 and the output y

  PredictorGains gains_;
  double period_s_;
  double one_minus_beta_;  // A's last diagonal entry
  Eigen::Vector4d x_ = Eigen::Vector4d::Zero();
};

}  // namespace hsa::control
