// hsa-simdev: the simulated rig of sim/ running in real time and served over Modbus TCP on
// 127.0.0.1, so the real modbus driver plugin (and mbpoll, or any Modbus master) can close the
// loop on it with no hardware. The register map is in tools/hsa_simdev/register_map.hpp.
// With --can IFACE it also serves the encoder and the valve electronics as CAN frames on that
// interface (tools/hsa_simdev/can_server.hpp), for the socketcan driver plugin.
//
// It prints one line once it listens, "hsa-simdev: listening on 127.0.0.1:<port>", so a test
// that asked for --port 0 learns the port; then it serves until --duration ends or SIGINT/SIGTERM.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "sim/rig.hpp"
#include "tools/hsa_simdev/can_server.hpp"
#include "tools/hsa_simdev/modbus_server.hpp"
#include "tools/hsa_simdev/rig_runner.hpp"

namespace {

std::atomic<bool> stop_requested{false};

extern "C" void on_signal(int) { stop_requested.store(true); }

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
  CLI11_PARSE(app, argc, argv);
  config.valve = valve == "servo" ? hsa::sim::ValveKind::servo : hsa::sim::ValveKind::proportional;

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);  // a client vanishing mid-reply is its problem, not ours

  try {
    const auto estop = estop_signal_only ? hsa::simdev::EstopWiring::signal_only
                                         : hsa::simdev::EstopWiring::cuts_valve_power;
    hsa::simdev::RigRunner rig(config, period_s, watchdog_ms * 1e-3, estop);
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
