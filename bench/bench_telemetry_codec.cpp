// Cost of putting one telemetry message on the wire and taking it off again: lcm-gen's encode()
// into a buffer sized once, and decode() from it. This is the per-message work hsad's LCM thread
// does for every published TELEMETRY sample (besides the send itself) and every subscriber does on
// receipt; at 8 axes × 1 kHz it runs 8000 times a second. The message carries realistic values so
// that nothing is special-cased (LCM encodes fixed-size fields, so the values do not change the
// cost, but zeros would hide a mistake in the round-trip check).
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <benchmark/benchmark.h>

#include "hsa/telemetry_t.hpp"

namespace {

hsa::telemetry_t sample_message() {
  hsa::telemetry_t t{};
  t.utime = 1'234'567'890;
  t.seq = 4'200'010;
  t.position_m = 0.15012;
  t.velocity_m_s = -0.0031;
  t.pressure_a_pa = 12.5e5;
  t.pressure_b_pa = 9.8e5;
  t.load_pressure_pa = 12.5e5 - 0.77 * 9.8e5;
  t.spool_position_m = 1.2e-4;
  t.setpoint_m = 0.15;
  t.following_error_m = -1.2e-4;
  t.valve_opening = 0.012;
  t.current_ref_a = 0.012;
  t.state = 2;
  t.holding = false;
  t.lateness_ns = 4100;
  t.lateness_max_ns = 812'000;
  t.exec_time_ns = 2300;
  t.exec_time_max_ns = 41'000;
  t.overruns = 3;
  t.setpoint_utime = 1'234'567'000;
  return t;
}

void BM_TelemetryEncode(benchmark::State& state) {
  const hsa::telemetry_t msg = sample_message();
  const int size = msg.getEncodedSize();
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(size));
  for (auto _ : state) {
    const int written = msg.encode(buffer.data(), 0, size);
    benchmark::DoNotOptimize(written);
    benchmark::DoNotOptimize(buffer.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * size);
  state.counters["bytes"] = size;
}

void BM_TelemetryDecode(benchmark::State& state) {
  const hsa::telemetry_t msg = sample_message();
  const int size = msg.getEncodedSize();
  std::vector<std::uint8_t> buffer(static_cast<std::size_t>(size));
  if (msg.encode(buffer.data(), 0, size) != size) throw std::runtime_error("telemetry_t::encode failed");
  hsa::telemetry_t out{};
  for (auto _ : state) {
    const int read = out.decode(buffer.data(), 0, size);
    benchmark::DoNotOptimize(read);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
  // The decoded message must be the one encoded: a benchmark of a decoder that fails is worthless.
  if (out.seq != msg.seq || out.position_m != msg.position_m || out.setpoint_utime != msg.setpoint_utime) {
    state.SkipWithError("decoded telemetry_t differs from the encoded one");
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * size);
  state.counters["bytes"] = size;
}

BENCHMARK(BM_TelemetryEncode);
BENCHMARK(BM_TelemetryDecode);

}  // namespace

BENCHMARK_MAIN();
