// The modbus driver plugin against hsa-simdev on 127.0.0.1: how fast its bus
// thread can cycle and how long one cycle's round trips take, next to raw libmodbus transactions
// on the same device in the same run.
//
// The benchmark starts hsa-simdev itself (path fixed at build time, --port 0, bounded by
// --duration) and uses the channel map of the shipped systemd/hsad-modbus-simdev.toml with
// poll_period_s = 1 µs (as fast as the bus allows), so one driver cycle is what hsad's does: write
// the valve enable (coil 0) and the valve command (holding registers 0-1), read the e-stop loop
// (discrete input 0) and position and pressures (input registers 0-5): four transactions.
//
//   BM_RawReadBlock           one modbus_read_input_registers of registers 0-5: the floor.
//   BM_RawCycle               the driver's four transactions, back to back, by hand.
//   BM_DriverCycle            the plugin seen from the RT side through read(), polled every
//                             ~10 µs: the interval between successive fresh samples is one bus
//                             cycle (the four round trips and the plugin's own work), and
//                             age_p50_us/age_p99_us say how old a sample is when read() first
//                             has it (acquired mid-request, then the rest of the cycle and the
//                             lock-free hand-over).
//   BM_DriverCycleUnobserved  read() once a millisecond, as hsad does; bus_rate_hz is the bus
//                             thread's cycle rate from the kernel's count of bytes sent on its
//                             connection, which costs it nothing. The age percentiles are those
//                             of the samples a 1 kHz loop works with.
//
// No command-to-echo time is measured: the plugin refuses an input channel overlapping an output,
// and hsa-simdev has no spare register to loop a command back through.
//
// Each reports p50_us, p99_us and max_us of its per-iteration times and rate_hz = 1 / their mean.
// Counts are fixed (Iterations, 5 repetitions of each: the console shows their mean, median and
// spread; --benchmark_format=json has every run) and every wait is bounded, so a dead device ends
// the run with an error instead of hanging it. The figures depend on the machine's load: nothing
// asserts them, and the medians are the ones to quote.
// Run: build/bin/bench_modbus
#include <benchmark/benchmark.h>
#include <linux/tcp.h>
#include <modbus/modbus.h>
#include <sys/prctl.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/modbus_raw_client.hpp"
#include "tests/drivers/test_modbus_support.hpp"
#include "tools/hsa_simdev/register_map.hpp"

namespace {

using Clock = std::chrono::steady_clock;  // CLOCK_MONOTONIC, the clock the plugin stamps with
using namespace std::chrono_literals;
namespace map = hsa::simdev;

int simdev_port = 0;  // set by main once hsa-simdev listens

// Per-iteration times → percentile counters. The vector is reserved before the timed loop.
class Samples {
 public:
  // `prefix` names the counters ("age_" → age_p50_us ...); rate_hz only without one.
  explicit Samples(benchmark::State& state, std::string prefix = "") : prefix_(std::move(prefix)) {
    us_.reserve(static_cast<std::size_t>(state.max_iterations));
  }
  void add(Clock::duration d) { us_.push_back(std::chrono::duration<double, std::micro>(d).count()); }
  void report(benchmark::State& state) {
    if (us_.empty()) return;
    std::sort(us_.begin(), us_.end());
    const auto at = [&](double q) { return us_[static_cast<std::size_t>(q * static_cast<double>(us_.size() - 1))]; };
    state.counters[prefix_ + "p50_us"] = at(0.50);
    state.counters[prefix_ + "p99_us"] = at(0.99);
    state.counters[prefix_ + "max_us"] = us_.back();
    if (!prefix_.empty()) return;
    double total_us = 0.0;
    for (const double us : us_) total_us += us;
    state.counters["rate_hz"] = 1e6 * static_cast<double>(us_.size()) / total_us;
  }

 private:
  std::string prefix_;
  std::vector<double> us_;
};

// A raw libmodbus client on hsa-simdev, with the plugin's response timeout (50 ms).
hsa::io::modbus_test::ModbusRawClient raw_client() {
  return hsa::io::modbus_test::ModbusRawClient(simdev_port, std::chrono::milliseconds(50));
}

void BM_RawReadBlock(benchmark::State& state) {
  hsa::io::modbus_test::ModbusRawClient client = raw_client();
  if (!client.connected()) return state.SkipWithError("cannot connect to hsa-simdev");
  std::uint16_t regs[6];
  Samples samples(state);
  for (auto _ : state) {
    const auto t0 = Clock::now();
    if (modbus_read_input_registers(client.get(), map::input_register::position_m, 6, regs) != 6) {
      return state.SkipWithError(modbus_strerror(errno));
    }
    samples.add(Clock::now() - t0);
  }
  samples.report(state);
}

void BM_RawCycle(benchmark::State& state) {
  hsa::io::modbus_test::ModbusRawClient client = raw_client();
  if (!client.connected()) return state.SkipWithError("cannot connect to hsa-simdev");
  std::uint16_t command[2] = {0, 0};  // 0.0f: the valve stays centred (and unpowered)
  std::uint16_t regs[6];
  std::uint8_t estop = 0;
  Samples samples(state);
  for (auto _ : state) {
    const auto t0 = Clock::now();
    if (modbus_write_registers(client.get(), map::holding_register::valve_command, 2, command) != 2 ||
        modbus_write_bit(client.get(), map::coil::valve_enable, 0) != 1 ||
        modbus_read_input_registers(client.get(), map::input_register::position_m, 6, regs) != 6 ||
        modbus_read_input_bits(client.get(), map::discrete_input::estop_loop_closed, 1, &estop) != 1) {
      return state.SkipWithError(modbus_strerror(errno));
    }
    samples.add(Clock::now() - t0);
  }
  samples.report(state);
}

// The shipped example's driver settings, pointed at this run's hsa-simdev and polled as fast as
// the bus allows.
toml::table driver_settings() {
  toml::table config = toml::parse_file(HSA_MODBUS_CONFIG);
  toml::table settings = *config["drivers"][0]["settings"].as_table();
  settings.insert_or_assign("port", simdev_port);
  settings.insert_or_assign("poll_period_s", 1e-6);
  return settings;
}

std::unique_ptr<hsa::io::DriverHandle> load_driver(benchmark::State& state) {
  try {
    return hsa::io::PluginLoader({HSA_PLUGIN_DIR}).load_driver("io", "modbus", driver_settings());
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return nullptr;
  }
}

// Polls `condition` until it holds or `timeout` passes, sleeping 10 µs between polls (main sets
// the timer slack to 1 µs, so the sleep is about that). That is shorter than a bus cycle, so the
// reader sees nearly every sample (a missed one shows as a doubled interval, in p99 at worst),
// and it leaves the cores to the bus thread and hsa-simdev: a reader spinning with yield() took
// a core from them on a 2-core machine and starved the bus thread for milliseconds.
template <class Condition>
bool poll_until(Condition condition, Clock::duration timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!condition()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(10));
  }
  return true;
}

hsa::io::Timestamp now() { return hsa::io::Timestamp(Clock::now().time_since_epoch()); }

void BM_DriverCycle(benchmark::State& state) {
  const auto driver = load_driver(state);
  if (!driver) return;
  const std::size_t encoder = *driver->find_channel("encoder");
  const auto fresh_stamp = [&]() -> std::optional<hsa::io::Timestamp> {
    driver->read(now(), 1ms);
    const hsa::io::ChannelSlot& s = driver->slots()[encoder];
    if (s.status != hsa::io::SampleStatus::ok) return std::nullopt;
    return s.timestamp;
  };
  // The first sample, then one fresh sample per iteration: the interval between their stamps
  // is one bus cycle (acquisition to acquisition, as the plugin measured it).
  std::optional<hsa::io::Timestamp> last;
  if (!poll_until([&] { return (last = fresh_stamp()).has_value(); }, 5s)) {
    return state.SkipWithError("no sample from hsa-simdev within 5 s");
  }
  Samples samples(state);
  Samples ages(state, "age_");
  for (auto _ : state) {
    std::optional<hsa::io::Timestamp> next;
    if (!poll_until([&] { return (next = fresh_stamp()) && *next != *last; }, 1s)) {
      return state.SkipWithError("no fresh sample within 1 s");
    }
    ages.add(std::chrono::duration_cast<Clock::duration>(now() - *next));
    samples.add(std::chrono::duration_cast<Clock::duration>(*next - *last));
    last = next;
  }
  samples.report(state);
  ages.report(state);
}

// Bytes this process has sent to hsa-simdev over TCP (the kernel's count, tcpi_bytes_sent), on
// the one connection the plugin holds to it; nullopt when there is none. Found by peer port
// among this process's sockets.
std::optional<std::uint64_t> bytes_sent_to_simdev() {
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    int fd = -1;
    try {
      fd = std::stoi(entry.path().filename().string());
    } catch (const std::exception&) {
      continue;
    }
    sockaddr_in peer{};
    socklen_t len = sizeof peer;
    if (getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &len) != 0 || peer.sin_family != AF_INET ||
        ntohs(peer.sin_port) != simdev_port) {
      continue;
    }
    tcp_info info{};
    socklen_t info_len = sizeof info;
    if (getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &info_len) == 0) return info.tcpi_bytes_sent;
  }
  return std::nullopt;
}

// The shipped map's requests, as sent (MBAP header 7 bytes + PDU): write multiple registers
// (2 registers) 17, write single coil 12, read input registers 12, read discrete inputs 12.
constexpr double bytes_per_cycle = 17 + 12 + 12 + 12;

// The driver as hsad runs it: read() once a millisecond, the bus thread free to cycle as fast as
// it can meanwhile. Its rate comes from the kernel's byte count on its connection, which costs
// the bus nothing; the percentiles are of the sample age each read() sees (how old the position
// the loop works with is).
void BM_DriverCycleUnobserved(benchmark::State& state) {
  const auto driver = load_driver(state);
  if (!driver) return;
  const std::size_t encoder = *driver->find_channel("encoder");
  if (!poll_until([&] {
        driver->read(now(), 1ms);
        return driver->slots()[encoder].status == hsa::io::SampleStatus::ok;
      }, 5s)) {
    return state.SkipWithError("no sample from hsa-simdev within 5 s");
  }
  const std::optional<std::uint64_t> bytes_before = bytes_sent_to_simdev();
  const auto t0 = Clock::now();
  Samples ages(state, "age_");
  for (auto _ : state) {
    std::this_thread::sleep_for(1ms);
    const hsa::io::Timestamp t = now();
    driver->read(t, 1ms);
    const hsa::io::ChannelSlot& s = driver->slots()[encoder];
    if (s.status != hsa::io::SampleStatus::ok) return state.SkipWithError("sample not ok");
    ages.add(std::chrono::duration_cast<Clock::duration>(t - s.timestamp));
  }
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const std::optional<std::uint64_t> bytes_after = bytes_sent_to_simdev();
  ages.report(state);
  if (!bytes_before || !bytes_after) return state.SkipWithError("the plugin's connection was not found");
  state.counters["bus_rate_hz"] = static_cast<double>(*bytes_after - *bytes_before) / bytes_per_cycle / elapsed_s;
}

BENCHMARK(BM_RawReadBlock)->Iterations(5000)->Repetitions(5)->DisplayAggregatesOnly()->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RawCycle)->Iterations(2000)->Repetitions(5)->DisplayAggregatesOnly()->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DriverCycle)->Iterations(2000)->Repetitions(5)->DisplayAggregatesOnly()->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DriverCycleUnobserved)->Iterations(2000)->Repetitions(5)->DisplayAggregatesOnly()->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  prctl(PR_SET_TIMERSLACK, 1000UL);  // 1 µs instead of 50: see poll_until
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // At most five minutes of device, whatever happens to the run; killed on exit anyway.
  hsa::io::modbus_test::ChildProcess simdev({HSA_SIMDEV, "--port", "0", "--duration", "300"});
  const auto line = simdev.read_line(10s);
  std::smatch m;
  if (!line || !std::regex_search(*line, m, std::regex("listening on 127\\.0\\.0\\.1:([0-9]+)"))) {
    std::fprintf(stderr, "bench_modbus: %s did not start\n", HSA_SIMDEV);
    return 1;
  }
  simdev_port = std::stoi(m[1]);
  std::printf("hsa-simdev on 127.0.0.1:%d; driver map from %s\n", simdev_port, HSA_MODBUS_CONFIG);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
