// hsad's own identification run, made deterministic: the real axis loop (supervisor, excitation,
// law) on the real sim plugin in lockstep (one 100 µs rig step per cycle, whatever the host does),
// excited by an EXCITE command as hsactl sends it, its 1 kHz telemetry written by the CSV writer
// of `hsactl excite --record`, and identified through `hsa-analyze identify`'s input path. The
// integration test (tests/integration/test_hsad_excite.py) makes the same run on the real hsad,
// where a host that keeps the RT thread off its deadlines spoils the record; this one cannot be.
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "control/identification/identify_run.hpp"
#include "control/laws/direct_servo/direct_servo_law.hpp"
#include "daemon/axis/axis_loop.hpp"
#include "drivers/plugin_loader.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"
#include "sim/cylinder.hpp"
#include "sim/rig.hpp"
#include "sim/small_signal.hpp"
#include "tests/analyze/identification_run.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace hsa {
namespace {

using namespace std::chrono_literals;
constexpr std::int64_t kPeriodNs = 100'000;  // hsad-sim.toml's base tick
constexpr int kTicksPerSample = 10;         // its 1 kHz cylinder loop and telemetry

daemon::AxisParams sim_axis() {
  daemon::AxisParams p;
  p.name = "lift";
  p.bindings.position = {"rig", "encoder", {}};
  p.bindings.pressure_a = {"rig", "pressure_a", {}};
  p.bindings.pressure_b = {"rig", "pressure_b", {}};
  p.bindings.valve_command = {"rig", "opening_cmd", {.low_limit = -1.0, .high_limit = 1.0}};
  p.bindings.valve_enable = {"rig", "valve_enable", {}};
  // hsad-sim.toml's [axes.pi], [axes.limits] and [axes.safety] that matter here.
  control::PiParams pi{.kp = 85.0, .ki = 460.0, .max_setpoint_rate_m_s = 0.2, .integral_dead_band_m = 5e-6};
  p.law = std::make_shared<control::DirectServoLaw>(pi, kTicksPerSample, control::GainBounds{170.0, 920.0});
  p.safety.soft_limit_low_m = 0.01;
  p.safety.soft_limit_high_m = 0.29;
  p.safety.following_error_max_m = 0.02;
  p.safety.max_speed_m_s = 0.2;
  p.safety.pressure_max_pa = 30e5;
  p.area_ratio = 0.77;
  return p;
}

TEST(IdentifyAxisRun, HsadsExcitationIdentifiesTheRigsPlant) {
  auto driver = io::PluginLoader({HSA_PLUGIN_DIR})
                    .load_driver("rig", "sim",
                                 toml::parse("valve = \"servo\"\ntiming = \"lockstep\"\nseed = 1\n"
                                             "initial_position_m = 0.15\n"));
  io::DriverHandle* drivers[] = {driver.get()};
  const daemon::AxisParams params = sim_axis();
  daemon::AxisLoop loop(params, daemon::bind_axis_signals(params.name, params.bindings, drivers));
  ASSERT_TRUE(driver->activate().ok());

  daemon::AxisInputsFromOperator op;
  std::int64_t t = 0;
  std::uint64_t tick = 0;
  std::ostringstream csv;
  ctl::write_telemetry_csv_header(csv);
  long rows = 0;
  const auto cycle = [&] {
    const io::Timestamp now{t};
    ASSERT_EQ(driver->read(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    loop.cycle(t, op, {}, tick);
    ASSERT_EQ(driver->write(now, std::chrono::nanoseconds(kPeriodNs)), io::IoStatus::ok);
    const daemon::AxisTelemetry& tm = loop.telemetry();
    if (tick % kTicksPerSample == 0 && tm.exciting) {
      // The fields `hsa-analyze identify` reads, as hsad's bridge fills them (message_conversion).
      hsa::telemetry_t m{};
      m.utime = t / 1000;
      m.seq = static_cast<std::int64_t>(tick);
      m.state = hsa::status_t::STATE_ENABLED;
      m.valve_enabled = tm.valve_enabled;
      m.setpoint_m = tm.setpoint;
      m.position_m = tm.position_m;
      m.following_error_m = tm.following_error_m;
      m.valve_opening = tm.opening;
      m.pressure_a_pa = tm.pressure_a_pa;
      m.pressure_b_pa = tm.pressure_b_pa;
      m.load_pressure_pa = tm.pressure_load_pa;
      m.exciting = tm.exciting;
      ctl::write_telemetry_csv_row(csv, m);
      ++rows;
    }
    t += kPeriodNs;
    ++tick;
  };
  for (int k = 0; k < 5; ++k) cycle();
  op.command.seq = 1;
  op.command.kind = daemon::CommandKind::enable;
  for (int k = 0; k < 5000; ++k) cycle();  // 0.5 s holding 150 mm
  ASSERT_EQ(loop.telemetry().state, daemon::AxisState::enabled);
  op.command = {};
  op.command.seq = 2;
  op.command.kind = daemon::CommandKind::excite;
  op.command.excite = {.working_point_m = 0.150,
                       .kind = control::ExcitationKind::prms,
                       .amplitude_m = 1e-3,
                       .switching_time_s = 0.3,
                       .levels = 5,
                       .seed = 3,
                       .duration_s = 25.0,
                       .kp_per_m = daemon::kDefaultExcitationKpPerM};
  for (int k = 0; k < 251'000; ++k) cycle();
  ASSERT_EQ(loop.telemetry().state, daemon::AxisState::enabled);
  ASSERT_FALSE(loop.telemetry().exciting);
  EXPECT_EQ(rows, 25'000);

  std::istringstream in(csv.str());
  const sim::RigConfig rig;
  const auto id =
      control::identification::identify_run(analyze::read_telemetry_run(in), test::identify_options_for(rig));
  const sim::SmallSignalPlant truth = sim::linearize(sim::Cylinder(rig.cylinder, rig.supply), 0.150, 0.0);
  std::printf("identified b0 %.0f (rig %.0f, %+.2f %%), b1 %.1f (rig %.1f, %+.2f %%), k01 %.1f (rig %.1f, %+.2f %%), "
              "fit %.3f, kp %.1f /m, delay %.2f ms\n",
              id.plant.b0.value, truth.b0, 100 * (id.plant.b0.value / truth.b0 - 1), id.plant.b1.value, truth.b1,
              100 * (id.plant.b1.value / truth.b1 - 1), id.plant.k01.value, truth.k01_mm_per_s,
              100 * (id.plant.k01.value / truth.k01_mm_per_s - 1), id.fit_index, id.kp_per_m, id.plant.delay_s * 1e3);
  EXPECT_NEAR(id.plant.b0.value / truth.b0, 1.0, 0.05);
  EXPECT_NEAR(id.plant.b1.value / truth.b1, 1.0, 0.05);
  EXPECT_NEAR(id.plant.k01.value / truth.k01_mm_per_s, 1.0, 0.05);
  EXPECT_GE(id.fit_index, 0.85);
  // id.kp_per_m is not compared: telemetry samples the rod on the first tick of each 1 ms window,
  // the cylinder loop on the tick the excitation started on, so the opening a row carries was
  // computed from a position up to 0.9 ms older than the row's (identify reads that as a delay and
  // a gain off by about 1 %). That the law runs kp = 200 with the integral off, sample by sample,
  // is pinned by tests/daemon/test_axis_loop.cpp.
}

}  // namespace
}  // namespace hsa
