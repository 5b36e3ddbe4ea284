// hsa-rig-demo: the simulated rig of Puglisi et al. (2015) under the paper's PI position loop, run in lockstep
// and printed as it moves. It is what the README's first command shows a new user until the
// daemon exists: the rod follows a sequence of setpoints (the paper's 10 mm step, long moves that
// hit the pump's flow limit, a 3 kg load added mid-run), one line per 20 ms of simulated time.
//
// The loop is the real control code (control/pi_controller) at its real rate (1 kHz) on the real
// rig model; only the pacing is the tool's: by default one simulated second per wall-clock second,
// so a person can watch it, or as fast as the machine runs with --speed 0.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

#include "control/pi_controller.hpp"
#include "sim/rig.hpp"

namespace {

struct Segment {
  double until_s;
  double setpoint_m;
  double load_kg;
  const char* what;
};

// The paper's Exp. 1 step at mid-stroke, then long moves and a load disturbance.
constexpr Segment kScript[] = {
    {0.5, 0.150, 0.0, "hold at 150 mm"},
    {2.0, 0.160, 0.0, "10 mm step (paper Exp. 1)"},
    {4.0, 0.250, 0.0, "long move up: pump flow limit"},
    {5.5, 0.250, 3.0, "3 kg added"},
    {7.5, 0.050, 3.0, "long move down"},
    {9.0, 0.150, 3.0, "back to mid-stroke"},
};

std::string bar(double position_m, double setpoint_m, double stroke_m) {
  constexpr int kWidth = 50;
  std::string line(kWidth + 1, '.');
  const auto column = [&](double y) {
    return static_cast<std::size_t>(std::lround(std::clamp(y / stroke_m, 0.0, 1.0) * kWidth));
  };
  line[column(setpoint_m)] = '|';
  line[column(position_m)] = '#';
  return "[" + line + "]";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lockstep run of the simulated hydraulic rig under the paper's PI position loop"};
  double speed = 1.0;
  app.add_option("--speed", speed, "simulated seconds per wall-clock second; 0 = as fast as possible")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  hsa::sim::RigConfig config;
  config.initial_position_m = kScript[0].setpoint_m;
  hsa::sim::Rig rig(config);
  hsa::control::PiController pi(hsa::control::PiParams{});
  pi.activate(rig.read().encoder_m.value);

  const double stroke = rig.cylinder().parameters().geometry.stroke_m;
  constexpr int kStepsPerLoop = 10;   // 10 kHz rig, 1 kHz cylinder loop
  constexpr int kLoopsPerLine = 20;   // a line every 20 ms
  std::printf("%7s %8s %8s %8s %7s %7s %7s  %s\n", "t[s]", "set[mm]", "rod[mm]", "err[mm]", "valve", "PA[bar]",
              "PB[bar]", "rod (#) and setpoint (|) over the 304 mm stroke");

  const auto start = std::chrono::steady_clock::now();
  const char* announced = nullptr;
  long loop = 0;
  for (const Segment& segment : kScript) {
    rig.set_load_mass(segment.load_kg);
    while (rig.time_s() < segment.until_s - 1e-9) {
      if (announced != segment.what) {
        std::printf("-- %s\n", segment.what);
        announced = segment.what;
      }
      const double u = pi.update(segment.setpoint_m, rig.read().encoder_m.value);
      rig.set_valve_command(u);
      for (int i = 0; i < kStepsPerLoop; ++i) rig.step();
      if (++loop % kLoopsPerLine == 0) {
        const hsa::sim::RigReadings r = rig.read();
        std::printf("%7.3f %8.2f %8.3f %+8.3f %+7.3f %7.2f %7.2f  %s\n", rig.time_s(), segment.setpoint_m * 1e3,
                    r.encoder_m.value * 1e3, (segment.setpoint_m - r.encoder_m.value) * 1e3, u,
                    r.pressure_a_pa.value / 1e5, r.pressure_b_pa.value / 1e5,
                    bar(r.encoder_m.value, segment.setpoint_m, stroke).c_str());
        std::fflush(stdout);
        if (speed > 0.0) {
          std::this_thread::sleep_until(start + std::chrono::duration<double>(rig.time_s() / speed));
        }
      }
    }
  }
  return 0;
}
