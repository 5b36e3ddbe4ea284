// How much faster than real time the full simulated rig runs on one core: one 100 µs step of the
// cylinder, the valve and all sensors. Reported as the counter `x_realtime` = simulated seconds per
// wall-clock second; docs/simulator.md quotes it (target ≥ 200×).
#include <benchmark/benchmark.h>

#include "sim/rig.hpp"

namespace {

void run_rig(benchmark::State& state, hsa::sim::ValveKind valve) {
  hsa::sim::RigConfig config;
  config.valve = valve;
  config.load_kg = 3.0;
  hsa::sim::Rig rig(config);
  // A moving rod: the valve opens and closes every 0.2 s, so the benchmark pays for the orifice
  // flows, the pump limit and the stiction logic, not just a rod at rest.
  const double open = valve == hsa::sim::ValveKind::servo ? 0.3 : rig.proportional_valve().bias_current() + 0.4;
  const double closed = valve == hsa::sim::ValveKind::servo ? -0.3 : rig.proportional_valve().bias_current() - 0.4;
  long step = 0;
  for (auto _ : state) {
    if (step % 2000 == 0) rig.set_valve_command((step / 2000) % 2 == 0 ? open : closed);
    rig.step();
    ++step;
    benchmark::DoNotOptimize(rig.read().encoder_m.value);
  }
  state.counters["x_realtime"] = benchmark::Counter(static_cast<double>(state.iterations()) * config.step_s,
                                                    benchmark::Counter::kIsRate);
}

void BM_RigStepServoValve(benchmark::State& state) { run_rig(state, hsa::sim::ValveKind::servo); }
void BM_RigStepProportionalValve(benchmark::State& state) { run_rig(state, hsa::sim::ValveKind::proportional); }

BENCHMARK(BM_RigStepServoValve);
BENCHMARK(BM_RigStepProportionalValve);

}  // namespace

BENCHMARK_MAIN();
