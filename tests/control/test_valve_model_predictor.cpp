// The state predictor driven by the identified valve model (control/valve_model_predictor.hpp):
// on a spool that moves as the model says, it follows the spool's 50 Hz motion with the bandwidth
// lowered, where the paper's predictor (Canuto et al. (2014) eqs 15–16) with the same eigenvalues
// lags; the LVDT's noise reaches the acceleration it outputs far less than through the paper's
// predictor with Table 2's eigenvalues; bad models are refused; nothing allocates.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>

#include "control/state_predictor.hpp"
#include "control/valve_law.hpp"
#include "control/valve_model_predictor.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::control {
namespace {

constexpr double kT = 1e-4;

// An identified valve as identified_valve() gives it for the paper's valve (round figures).
IdentifiedValve paper_like() {
  return {.gain_m_per_a = 1.0 / 548.3, .rest_position_m = -2.5e-3, .natural_frequency_hz = 50.0,
          .damping_ratio = 0.3, .magnetic_lag_s = 1.5e-3, .width_a = 0.3, .delay_s = 0.5e-3, .current_max_a = 3.0};
}

// The valve the model describes, integrated finer than the predictor samples (10 substeps) so that
// it is the continuous model, not the predictor's own discretisation: the current δ late, the play at
// its mean, the lag τa, the spring–mass (eqs 1–3, 6).
class ModelValve {
 public:
  explicit ModelValve(const IdentifiedValve& v, double current_a) : v_(v) {
    force_ = current_a - 0.5 * v.width_a;
    x_ = v.rest_position_m + v.gain_m_per_a * force_;
    line_.fill(current_a);
  }
  void step(double current_a) {
    const int delay = static_cast<int>(std::lround(v_.delay_s / kT));
    const double entering = line_[static_cast<std::size_t>(head_)];
    line_[static_cast<std::size_t>(head_)] = current_a;
    head_ = (head_ + 1) % delay;
    const double w0 = 2.0 * std::numbers::pi * v_.natural_frequency_hz;
    const double h = kT / 10.0;
    for (int k = 0; k < 10; ++k) {
      force_ += h / v_.magnetic_lag_s * ((entering - 0.5 * v_.width_a) - force_);
      a_ = w0 * w0 * (v_.rest_position_m + v_.gain_m_per_a * force_ - x_) - 2.0 * v_.damping_ratio * w0 * vel_;
      vel_ += h * a_;
      x_ += h * vel_;
    }
  }
  [[nodiscard]] double x() const { return x_; }
  [[nodiscard]] double v() const { return vel_; }

 private:
  IdentifiedValve v_;
  double force_ = 0.0, x_ = 0.0, vel_ = 0.0, a_ = 0.0;
  std::array<double, 16> line_{};
  int head_ = 0;
};

// Half of Table 2's γ: the eigenvalues identified_model_predictor() uses.
std::array<double, 4> halved() {
  std::array<double, 4> g = kTable2Gamma;
  for (double& x : g) x *= 0.5;
  return g;
}

TEST(ValveModelPredictor, FollowsTheSpoolsModeWhereThePapersPredictorWithTheSameEigenvaluesLags) {
  const IdentifiedValve v = paper_like();
  const double bias = -v.rest_position_m / v.gain_m_per_a + 0.5 * v.width_a;
  ModelValve valve(v, bias);
  ValveModelPredictor model({.enabled = true, .valve = v, .gamma = halved()}, kT);
  StatePredictor paper(predictor_gains(halved()), kT);
  model.reset(valve.x());
  paper.reset(valve.x());
  double model_err = 0.0, paper_err = 0.0, motion = 0.0;
  for (int i = 0; i < 4000; ++i) {
    // Steps of ±0.4 A every 50 ms ring the 50 Hz mode; between them the spool sits still.
    const double current = bias + ((i / 500) % 2 == 0 ? 0.4 : -0.4);
    const PredictorOutput m = model.update(valve.x());
    const PredictorOutput p = paper.update(valve.x());
    model.commanded(current);
    if (i >= 1000) {  // after both have settled on the first steps
      model_err = std::max(model_err, std::abs(m.velocity_m_s - valve.v()));
      paper_err = std::max(paper_err, std::abs(p.velocity_m_s - valve.v()));
      motion = std::max(motion, std::abs(valve.v()));
    }
    valve.step(current);
  }
  std::printf("  spool speed up to %.1f mm/s; velocity error: model predictor %.2f mm/s, paper's %.2f mm/s\n",
              motion * 1e3, model_err * 1e3, paper_err * 1e3);
  ASSERT_GT(motion, 0.05);  // the steps do move the spool
  EXPECT_LT(model_err, 0.2 * paper_err);
  EXPECT_LT(model_err, 0.05 * motion);
}

TEST(ValveModelPredictor, TheLvdtNoiseReachesItsAccelerationFarLessThanThroughTable2) {
  const IdentifiedValve v = paper_like();
  const double bias = -v.rest_position_m / v.gain_m_per_a + 0.5 * v.width_a;
  ValveModelPredictor model(identified_model_predictor(v), kT);
  StatePredictor paper(predictor_gains(kTable2Gamma), kT);
  const double rest = v.rest_position_m + v.gain_m_per_a * (bias - 0.5 * v.width_a);
  model.reset(rest);
  paper.reset(rest);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-6);  // the LVDT's 1 µm rms
  double model_sq = 0.0, paper_sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double y = rest + noise(rng);
    const double am = model.update(y).acceleration_m_s2;
    const double ap = paper.update(y).acceleration_m_s2;
    model.commanded(bias);
    if (i >= 2000) {
      model_sq += am * am;
      paper_sq += ap * ap;
    }
  }
  const double model_rms = std::sqrt(model_sq / (n - 2000)), paper_rms = std::sqrt(paper_sq / (n - 2000));
  std::printf("  acceleration from 1 um rms of LVDT noise: model predictor %.2f m/s2 rms, Table 2 %.2f m/s2 rms\n",
              model_rms, paper_rms);
  EXPECT_LT(model_rms, 0.5 * paper_rms);
}

TEST(ValveModelPredictor, RefusesAModelThatIsNotAValve) {
  const auto refused = [](auto change) {
    ValveModelPredictorParams p{.enabled = true, .valve = paper_like()};
    change(p);
    EXPECT_THROW(ValveModelPredictor(p, kT), std::invalid_argument);
  };
  refused([](ValveModelPredictorParams& p) { p.valve.gain_m_per_a = 0.0; });
  refused([](ValveModelPredictorParams& p) { p.valve.natural_frequency_hz = -50.0; });
  refused([](ValveModelPredictorParams& p) { p.valve.damping_ratio = NAN; });
  refused([](ValveModelPredictorParams& p) { p.valve.magnetic_lag_s = 0.0; });
  refused([](ValveModelPredictorParams& p) { p.valve.width_a = -0.1; });
  refused([](ValveModelPredictorParams& p) { p.valve.delay_s = 2e-3; });  // 20 samples
  refused([](ValveModelPredictorParams& p) { p.valve.rest_position_m = INFINITY; });
  refused([](ValveModelPredictorParams& p) { p.gamma[2] = 0.0; });
  EXPECT_THROW(ValveModelPredictor({.enabled = true, .valve = paper_like()}, 0.0), std::invalid_argument);
}

TEST(ValveModelPredictor, UpdateAndCommandedDoNotAllocate) {
  ValveModelPredictor model(identified_model_predictor(paper_like()), kT);
  model.reset(0.0);
  const long before = test::thread_allocations();
  for (int i = 0; i < 3000; ++i) {
    model.update(1e-4 * std::sin(0.01 * i));
    model.commanded(1.5 + 0.2 * std::sin(0.02 * i));
  }
  EXPECT_EQ(test::thread_allocations(), before);
}

}  // namespace
}  // namespace hsa::control
