// hsa-simdev: the simulated rig of sim/ running in real time and served over Modbus TCP on
// 127.0.0.1, so the real modbus driver plugin (and mbpoll, or any Modbus master) can close the
// loop on it with no hardware. The register map is in tools/hsa_simdev/register_map.hpp.
// With --can IFACE it also serves the encoder and the valve electronics as CAN frames on that
// interface (tools/hsa_simdev/can_server.hpp), for the socketcan driver plugin.
//
// It prints one line once it listens, "hsa-simdev: listening on 127.0.0.1:<port>", so a test
// that asked for --port 0 learns the port; then it serves until --duration ends or SIGINT/SIGTERM.
//
// --delay-probe adds a square wave to the position it serves and times, on its own clock, each
// edge's sample to the first valve command that reacts (tools/hsa_simdev/delay_probe.hpp); the
// delays go to --delay-probe-out as JSON when it exits, and a summary line to stdout.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <algorithm>
#include <exception>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/rig.hpp"
#include "tools/hsa_simdev/can_server.hpp"
#include "tools/hsa_simdev/modbus_server.hpp"
#include "tools/hsa_simdev/rig_runner.hpp"

namespace {

std::atomic<bool> stop_requested{false};

extern "C" void on_signal(int) { stop_requested.store(true); }

// The probe's delays as JSON: the settings, the counts and every delay in ns, in edge order.
void write_probe_json(const std::string& path, const hsa::simdev::DelayProbe& probe, double period_s) {
  const hsa::simdev::DelayProbeSettings& s = probe.settings();
  const nlohmann::json out = {
      {"step_m", s.step_m},          {"hold_s", static_cast<double>(s.hold_ns) * 1e-9},
      {"jitter_s", static_cast<double>(s.jitter_ns) * 1e-9}, {"threshold", s.threshold},
      {"rig_period_s", period_s},    {"edges", probe.edges()},
      {"misses", probe.misses()},    {"delays_ns", probe.delays_ns()}};
  std::ofstream f(path);
  f << out.dump() << "\n";
  if (!f) throw std::runtime_error("cannot write " + path);
}

void print_probe_summary(const hsa::simdev::DelayProbe& probe) {
  std::vector<std::int64_t> d = probe.delays_ns();
  std::sort(d.begin(), d.end());
  const auto at = [&](double q) { return d.empty() ? 0.0 : static_cast<double>(d[static_cast<std::size_t>(q * static_cast<double>(d.size() - 1))]) * 1e-3; };
  std::printf("hsa-simdev: delay probe: %llu edges, %zu reactions, %llu misses; sample to command p50 %.0f us, "
              "p99 %.0f us, max %.0f us\n",
              static_cast<unsigned long long>(probe.edges()), d.size(), static_cast<unsigned long long>(probe.misses()),
              at(0.5), at(0.99), d.empty() ? 0.0 : static_cast<double>(d.back()) * 1e-3);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulated hydraulic rig served over Modbus TCP on 127.0.0.1"};
  int port = 1502;
  double duration_s = 0.0;
  std::string valve = "servo";
  hsa::sim::RigConfig config;
  double period_s = 1e-3;
  std::string can_interface;
  int watchdog_ms = 100;
  bool estop_signal_only = false;
  app.add_option("--port", port, "TCP port on 127.0.0.1; 0 picks a free one (printed)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--duration", duration_s, "seconds to serve, then exit; 0 = until SIGINT/SIGTERM")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--valve", valve, "servo | proportional")
      ->check(CLI::IsMember({"servo", "proportional"}))
      ->capture_default_str();
  app.add_option("--load-kg", config.load_kg, "load on the rod")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--initial-position-m", config.initial_position_m, "rod position at start")->capture_default_str();
  app.add_option("--seed", config.seed, "noise seed")->capture_default_str();
  app.add_option("--step-s", config.step_s, "the model's integration step")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--period-s", period_s, "real-time pacing period: the rig advances this much per tick")
      ->check(CLI::Range(1e-4, 0.1))
      ->capture_default_str();
  app.add_option("--can", can_interface,
                 "also serve the encoder (0x181) and the valve (0x201) on this CAN interface, e.g. vcan0");
  app.add_option("--watchdog-ms", watchdog_ms,
                 "communication watchdog: with no master write (Modbus) or valve frame (CAN) for this "
                 "long, the valve goes to 0 and its enable off, latched until the master writes the "
                 "enable off; 0 = off (the last command holds)")
      ->check(CLI::Range(0, 60000))
      ->capture_default_str();
  app.add_flag("--estop-signal-only", estop_signal_only,
               "the e-stop button only opens the e-stop input; by default it also cuts the valve's "
               "power, as an e-stop chain does, until it is released and the master writes the enable off");
  // The test hooks are registers, not flags, so that a test can switch them mid-run.
  app.footer(
      "Test hooks, coils any Modbus connection may write (tools/hsa_simdev/register_map.hpp):\n"
      "  coil 8  e-stop button: 1 = pressed\n"
      "  coil 9  refuse valve command: 1 = the master's writes to the valve command (holding\n"
      "          registers 0-1) are refused with exception 03 (illegal data value) and counted in\n"
      "          input register 45; the enable coil is still taken. 0 = accepted again.");
  bool delay_probe = false;
  hsa::simdev::DelayProbeSettings probe;
  double probe_hold_s = 0.02;
  double probe_jitter_s = 0.003;
  std::string probe_out;
  app.add_flag("--delay-probe", delay_probe,
               "sensor-to-actuator delay probe: add a square wave to the served position and time each "
               "edge's sample to the first valve command that reacts (delay_probe.hpp)");
  app.add_option("--delay-probe-step-m", probe.step_m, "the square wave's peak-to-peak, m; under hsad's encoder_jump_m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--delay-probe-hold-s", probe_hold_s, "time between edges, at least; longer than any delay")
      ->check(CLI::Range(1e-3, 10.0))
      ->capture_default_str();
  app.add_option("--delay-probe-jitter-s", probe_jitter_s, "plus a pseudo-random 0..this, so edges fall at every bus phase")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--delay-probe-threshold", probe.threshold,
                 "valve command change that marks the reaction: above the loop's change per write, "
                 "below Kp x step")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--delay-probe-out", probe_out, "write the delays (ns) and counts as JSON here on exit");
  CLI11_PARSE(app, argc, argv);
  probe.hold_ns = static_cast<std::int64_t>(std::llround(probe_hold_s * 1e9));
  probe.jitter_ns = static_cast<std::int64_t>(std::llround(probe_jitter_s * 1e9));
  config.valve = valve == "servo" ? hsa::sim::ValveKind::servo : hsa::sim::ValveKind::proportional;

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);  // a client vanishing mid-reply is its problem, not ours

  try {
    const auto estop = estop_signal_only ? hsa::simdev::EstopWiring::signal_only
                                         : hsa::simdev::EstopWiring::cuts_valve_power;
    hsa::simdev::RigRunner rig(config, period_s, watchdog_ms * 1e-3, estop);
    if (delay_probe) rig.enable_delay_probe(probe);
    hsa::simdev::ModbusServer server(rig, port, config.valve == hsa::sim::ValveKind::proportional, watchdog_ms);
    std::unique_ptr<hsa::simdev::CanServer> can;
    if (!can_interface.empty()) can = std::make_unique<hsa::simdev::CanServer>(rig, can_interface, period_s);
    rig.start();
    if (can) can->start();
    std::printf("hsa-simdev: listening on 127.0.0.1:%d\n", server.port());
    if (can) {
      std::printf("hsa-simdev: serving CAN on %s (position 0x181, valve 0x201, status 0x281)\n",
                  can_interface.c_str());
    }
    if (watchdog_ms > 0) {
      std::printf("hsa-simdev: communication watchdog %d ms\n", watchdog_ms);
    } else {
      std::printf("hsa-simdev: communication watchdog off\n");
    }
    std::printf("hsa-simdev: e-stop %s\n", estop_signal_only ? "opens its input only" : "cuts the valve's power");
    std::fflush(stdout);
    const auto until = duration_s > 0.0
                           ? std::chrono::steady_clock::now() +
                                 std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(duration_s))
                           : std::chrono::steady_clock::time_point::max();
    server.serve(stop_requested, until);
    if (can) {
      can->stop();
      std::printf("hsa-simdev: CAN: %llu position frames sent, %llu valve commands applied, %llu of the "
                  "wrong length\n",
                  static_cast<unsigned long long>(can->frames_sent()),
                  static_cast<unsigned long long>(can->commands_applied()),
                  static_cast<unsigned long long>(can->length_errors()));
    }
    rig.stop();
    if (const auto result = rig.delay_probe()) {
      print_probe_summary(*result);
      if (!probe_out.empty()) write_probe_json(probe_out, *result, period_s);
    }
    std::printf("hsa-simdev: served %llu requests; %llu real-time skips; %llu watchdog trips\n",
                static_cast<unsigned long long>(server.requests()),
                static_cast<unsigned long long>(rig.skips()),
                static_cast<unsigned long long>(rig.watchdog().trips));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hsa-simdev: %s\n", e.what());
    return 1;
  }
  return 0;
}
