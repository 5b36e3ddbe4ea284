// Cost of the flight recorder per base tick on the RT thread: one row filled from the axis's
// telemetry and committed into its ring (daemon/recorder/capture_ring.hpp), with the ring at its
// default size (2 s at 10 kHz, two buffers of 20 000 rows: more than the caches hold, so the
// stores go to memory as they do in hsad). A second case triggers a capture every 3 s of ticks
// and has the writer hand the buffer back at once, so that the freeze is in the average too.
#include <cstdint>

#include <benchmark/benchmark.h>

#include "daemon/axis/axis_telemetry.hpp"
#include "daemon/recorder/capture_ring.hpp"

namespace {

using namespace hsa::daemon;

// What AxisRecorder::record writes, from a telemetry record that changes every tick.
inline void fill(RecorderRow& r, const AxisTelemetry& tm, std::uint64_t tick) {
  r.seq = tick;
  r.tick = tick;
  r.skipped = 0;
  r.t_ns = tm.t_ns;
  r.setpoint = tm.setpoint;
  r.rod_setpoint_m = tm.setpoint;
  r.position_m = tm.position_m;
  r.velocity_m_s = tm.velocity_m_s;
  r.following_error_m = tm.following_error_m;
  r.opening = tm.opening;
  r.command = tm.command;
  r.spool_m = tm.spool_position_m;
  r.pressure_a_pa = tm.pressure_a_pa;
  r.pressure_b_pa = tm.pressure_b_pa;
  r.integral = tm.kp;
  r.active_faults = tm.active_faults;
  r.lateness_ns = 1000;
  r.state = static_cast<std::uint8_t>(tm.state);
  r.mode = static_cast<std::uint8_t>(tm.mode);
  r.valve_enabled = tm.valve_enabled ? 1 : 0;
  r.fault_reason = static_cast<std::uint8_t>(tm.fault.reason);
}

void run(benchmark::State& state, std::uint64_t trigger_every) {
  CaptureRing ring(20'000, 5'000);
  AxisTelemetry tm{};
  std::uint64_t tick = 0;
  for (auto _ : state) {
    tm.t_ns += 100'000;
    tm.position_m += 1e-7;
    RecorderRow& r = ring.slot();
    fill(r, tm, tick);
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
