#include "control/state_predictor.hpp"

#include <stdexcept>
#include <string>

namespace hsa::control {

PredictorCoefficients predictor_coefficients(const std::array<double, 4>& gamma) {
  for (double g : gamma) {
    if (!(g > 0.0 && g <= 1.0))
      throw std::invalid_argument("state predictor: complementary eigenvalue " + std::to_string(g) +
                                  " is outside (0, 1]");
  }
  // Expand ∏(γ + γ_k) one factor at a time: p holds the coefficients, p[0] the constant term.
  std::array<double, 5> p{1.0, 0.0, 0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < gamma.size(); ++k) {
    for (std::size_t j = k + 1; j > 0; --j) p[j] = p[j - 1] + gamma[k] * p[j];
    p[0] *= gamma[k];
  }
  return {.c3 = p[3], .c2 = p[2], .c1 = p[1], .c0 = p[0]};
}

PredictorGains predictor_gains(const std::array<double, 4>& gamma, double l_d) {
  const PredictorCoefficients c = predictor_coefficients(gamma);
  const double beta = c.c3;
  const double l_a = c.c2;
  const double l_d_min = c.c1 - beta * l_a;  // negative by eq 20
  const double l_d_max = c.c0 / beta;
  if (!(l_d >= l_d_min && l_d <= l_d_max))
    throw std::invalid_argument("state predictor: l_d = " + std::to_string(l_d) + " is outside [" +
                                std::to_string(l_d_min) + ", " + std::to_string(l_d_max) +
                                "] (eq 21)");
  return {.beta = beta,
          .l_a = l_a,
          .l_d = l_d,
          .m_a = c.c1 - beta * l_a - l_d,
          .m_d = c.c0 - beta * l_d};
}

Eigen::Matrix4d predictor_state_matrix(const PredictorGains& g) {
  Eigen::Matrix4d a;
  // clang-format off
  a <<  1.0,    1.0, 0.0, 0.0,
       -g.l_a,  1.0, 1.0, g.m_a,
       -g.l_d,  0.0, 1.0, g.m_d,
       -1.0,    0.0, 0.0, 1.0 - g.beta;
  // clang-format on
  return a;
}

Eigen::Vector4d predictor_input_vector(const PredictorGains& g) { return {0.0, g.l_a, g.l_d, 1.0}; }

StatePredictor::StatePredictor(const PredictorGains& gains, double period_s)
    : gains_(gains),
      period_s_(period_s),
      one_minus_beta_(1.0 - gains.beta) {
  if (!(period_s > 0.0)) throw std::invalid_argument("StatePredictor: period must be > 0");
}

void StatePredictor::reset(double position_m) noexcept { x_ = {position_m, 0.0, 0.0, 0.0}; }

// Out of line and cold: with the loop inside update() the compiler stopped inlining the state
// update on the every-tick path (bench_control_tick measured it).
[[gnu::noinline, gnu::cold]] void StatePredictor::catch_up(double measured_position_m, std::uint64_t elapsed) noexcept {
  for (std::uint64_t j = 1; j < elapsed && j <= kMaxCatchUp; ++j) (void)step(measured_position_m);
}

PredictorOutput StatePredictor::step(double measured_position_m) noexcept {
  // Eq 15 written out with A's zeros and ones: every correction is the innovation
  // e = y_x - x times the column of L, so x(i+1) = A x(i) + L y_x(i) costs seven multiply-adds
  // instead of the dense 4×4 product's sixteen (bench_control_tick measured the difference).
  const double innovation = measured_position_m - x_(0);
  // Third row of C_m, D_m: a = d + w_a, with w_a = l_a·(y_x - x) + m_a·q from eq 17.
  const double acceleration = x_(2) + gains_.l_a * innovation + gains_.m_a * x_(3);
  const PredictorOutput out{.position_m = x_(0),
                            .velocity_m_s = x_(1) / period_s_,
                            .acceleration_m_s2 = acceleration / (period_s_ * period_s_)};
  x_ = Eigen::Vector4d(x_(0) + x_(1), x_(1) + acceleration, x_(2) + gains_.m_d * x_(3) + gains_.l_d * innovation,
                       one_minus_beta_ * x_(3) + innovation);
  return out;
}

}  // namespace hsa::control
