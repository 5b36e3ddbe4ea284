// Cost of the gain gate (control/gain_gate.hpp) on the 33 plants of Table A3: what hsad's
// operator thread spends on one `hsactl gains` (and each axis on the configuration's gains) before
// the gains reach the RT thread. One benchmark per outcome, since a refusal on stability does the
// same work as a pass: every plant's poles and margins, and the small-gain norm.
#include <benchmark/benchmark.h>

#include "control/loop_analysis.hpp"
#include "control/gain_gate.hpp"

namespace {

using namespace hsa::control;

void judge(benchmark::State& state, PiGainsSi gains, bool with_uncertainty) {
  GatePlantSet set = table_a3_plant_set();
  if (!with_uncertainty) set.uncertainty.reset();
  for (auto _ : state) {
    const GateVerdict v = judge_gains(set, {}, gains);
    benchmark::DoNotOptimize(v.refusal.data());
  }
  state.counters["plants"] = static_cast<double>(set.plants.size());
}

// The paper's gains: they pass.
void BM_GainGateTableA3PaperGains(benchmark::State& state) { judge(state, {85.0, 460.0}, true); }
// kp 400: unstable on some plants, refused.
void BM_GainGateTableA3Unstable(benchmark::State& state) { judge(state, {400.0, 460.0}, true); }
// Margins only (a set without W1): the share of the small-gain norm.
void BM_GainGateTableA3MarginsOnly(benchmark::State& state) { judge(state, {85.0, 460.0}, false); }

// One plant's margins, the part that grows with the set (in closed form, loop_analysis.hpp).
void BM_MarginsOnePlant(benchmark::State& state) {
  const CylinderPlant p = kTableA3[0].plant();
  for (auto _ : state) benchmark::DoNotOptimize(stability_margins(p, {85.0, 460.0}));
}

}  // namespace

BENCHMARK(BM_GainGateTableA3PaperGains)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GainGateTableA3Unstable)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GainGateTableA3MarginsOnly)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarginsOnePlant)->Unit(benchmark::kMicrosecond);
