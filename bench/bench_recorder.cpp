// Cost of the flight recorder per base tick on the RT thread: one row filled from the axis's
// telemetry by the recorder's own fill_row and committed into its ring (daemon/recorder/capture_ring.hpp), with the ring at its
// default size (2 s at 10 kHz, two buffers of 20 000 rows: more than the caches hold, so the
// stores go to memory as they do in hsad). A second case triggers a capture every 3 s of ticks
// and has the writer hand the buffer back at once, so that the freeze is in the average too.
#include <cstdint>

#include <benchmark/benchmark.h>

#include "daemon/axis/axis_telemetry.hpp"
#include "daemon/recorder/axis_recorder.hpp"
#include "daemon/recorder/capture_ring.hpp"

namespace {

using namespace hsa::daemon;

void run(benchmark::State& state, std::uint64_t trigger_every) {
  CaptureRing ring(20'000, 5'000);
  AxisTelemetry tm{};
  std::uint64_t tick = 0;
  for (auto _ : state) {
    tm.t_ns += 100'000;
    tm.position_m += 1e-7;
    RecorderRow& r = ring.slot();
    fill_row(r, tm, tm.setpoint, tm.kp, tick, tick, 0, 1000);
    if (trigger_every != 0 && tick % trigger_every == 0) ring.trigger({.tick = tick});
    r.exec_ns = 20'000;
    ring.commit();
    if (trigger_every != 0 && ring.take() != nullptr) ring.release();
    ++tick;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_RecorderRow(benchmark::State& state) { run(state, 0); }
void BM_RecorderRowWithCaptures(benchmark::State& state) { run(state, 30'000); }

BENCHMARK(BM_RecorderRow);
BENCHMARK(BM_RecorderRowWithCaptures);

}  // namespace

BENCHMARK_MAIN();
