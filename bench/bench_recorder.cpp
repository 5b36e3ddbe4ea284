// Cost of the flight recorder per base tick on the RT thread: one row filled from the axis's
// telemetry by the recorder's own fill_row and committed into its ring (daemon/recorder/capture_ring.hpp), with the ring at its
// default size (2 s at 10 kHz, two buffers of 20 000 rows: more than the caches hold, so the
// stores go to memory as they do in hsad). A second case triggers a capture every 3 s of ticks
// and has the writer hand the buffer back at once, so that the freeze is in the average too. A
// third runs AxisRecorder::commit with an operator's condition armed (following_error_m above a
// level, repeat; capture_condition.hpp), crossed every 3 s of ticks: the condition's evaluation
// on every row is in the average.
#include <cstdint>
#include <memory>

#include <benchmark/benchmark.h>

#include "daemon/axis/axis_telemetry.hpp"
#include "daemon/recorder/axis_recorder.hpp"
#include "daemon/recorder/capture_ring.hpp"
#include "daemon/recorder/recorder_signals.hpp"

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

void BM_RecorderRowWithCondition(benchmark::State& state) {
  AxisRecorder rec(std::make_unique<CaptureRing>(20'000, 5'000));
  CaptureRequest arm;
  arm.action = CaptureAction::arm;
  arm.signal_index = static_cast<std::int16_t>(recorder_signal_index("following_error_m"));
  arm.level = 0.001;
  arm.repeat = true;
  rec.apply(arm, 1);
  AxisTelemetry tm{};
  std::uint64_t tick = 0;
  for (auto _ : state) {
    tm.t_ns += 100'000;
    tm.following_error_m = tick % 30'000 < 10 ? 0.002 : 0.0;
    fill_row(rec.ring().slot(), tm, tm.setpoint, tm.kp, tick, tick, 0, 1000);
    rec.commit(20'000);
    if (rec.ring().take() != nullptr) rec.ring().release();
    ++tick;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_RecorderRow(benchmark::State& state) { run(state, 0); }
void BM_RecorderRowWithCaptures(benchmark::State& state) { run(state, 30'000); }

BENCHMARK(BM_RecorderRow);
BENCHMARK(BM_RecorderRowWithCaptures);
BENCHMARK(BM_RecorderRowWithCondition);

}  // namespace

BENCHMARK_MAIN();
