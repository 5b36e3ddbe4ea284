// Cost of the control law per 100 µs tick: the valve loop (state predictor + eq 31 law) every
// tick, and the PI cylinder loop on one tick in ten. The inputs are precomputed so that only the
// control code is timed.
#include <array>
#include <cmath>
#include <numbers>

#include <benchmark/benchmark.h>

#include "control/cascade.hpp"

namespace {

using namespace hsa::control;

constexpr std::size_t kSamples = 1000;  // 0.1 s of valve-loop ticks, a whole period of each input

struct Inputs {
  std::array<double, kSamples> rod{};
  std::array<double, kSamples> spool{};
};

const Inputs& inputs() {
  static const Inputs in = [] {
    Inputs s;
    for (std::size_t k = 0; k < kSamples; ++k) {
      const double phase = 2.0 * std::numbers::pi * static_cast<double>(k) / kSamples;
      s.rod[k] = 0.15 + 1e-3 * std::sin(phase);       // 10 Hz around mid-stroke
      s.spool[k] = 0.5e-3 * std::sin(7.0 * phase);   // 70 Hz
    }
    return s;
  }();
  return in;
}

CascadeParams params(ValveDrive drive) {
  CascadeParams p;
  p.drive = drive;
  p.valve.bias_current_a = 1.2;
  p.valve.feedforward_a_per_m = 250.0;
  p.valve.integral_a_per_m_s = 5e4;
  p.valve.proportional_a_per_m = 3300.0;
  p.valve.dead_band_compensation_a = 0.15;
  p.valve.dead_band_error_m = 5e-6;
  p.valve.velocity_a_per_m_s = 2.0;
  p.valve.acceleration_a_per_m_s2 = 1e-3;
  return p;
}

void run_cascade(benchmark::State& state, ValveDrive drive) {
  const Inputs& in = inputs();
  Cascade cascade(params(drive));
  cascade.activate(in.rod[0], in.spool[0]);
  std::size_t k = 0;
  for (auto _ : state) {
    const LawOutput out = cascade.tick({.rod_setpoint_m = 0.15, .rod_position_m = in.rod[k], .spool_position_m = in.spool[k]});
    benchmark::DoNotOptimize(out);
    if (++k == kSamples) k = 0;
  }
}

// One 10 kHz tick of the proportional-valve cascade, the PI's share averaged in.
void BM_CascadeTick(benchmark::State& state) { run_cascade(state, ValveDrive::proportional); }
BENCHMARK(BM_CascadeTick);

// The servo-valve case: the PI's share only.
void BM_CascadeTickDirect(benchmark::State& state) { run_cascade(state, ValveDrive::direct); }
BENCHMARK(BM_CascadeTickDirect);

// The parts, for reference.
void BM_PredictorAndLaw(benchmark::State& state) {
  const Inputs& in = inputs();
  const CascadeParams p = params(ValveDrive::proportional);
  StatePredictor predictor(p.predictor, p.valve.period_s);
  ValveLaw law(p.valve);
  predictor.reset(in.spool[0]);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(law.update(0.0, predictor.update(in.spool[k])));
    if (++k == kSamples) k = 0;
  }
}
BENCHMARK(BM_PredictorAndLaw);

void BM_PiUpdate(benchmark::State& state) {
  const Inputs& in = inputs();
  PiController pi(PiParams{});
  pi.activate(in.rod[0]);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(pi.update(0.15, in.rod[k]));
    if (++k == kSamples) k = 0;
  }
}
BENCHMARK(BM_PiUpdate);

}  // namespace
