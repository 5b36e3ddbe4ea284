// `hsa-analyze identify`'s fit on runs made on the simulated rig (identification_run.hpp), read
// through the same CSV path as a recorded run, against the rig's own small-signal plant
// (sim::linearize) and parameters at the same working point: the paper's nine step cases and two
// rigs far from the paper's that nothing was tuned on.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "control/identification/identify_run.hpp"
#include "control/loop_analysis.hpp"
#include "control/pi_controller.hpp"
#include "sim/small_signal.hpp"
#include "tests/analyze/identification_run.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"

namespace hsa {
namespace {

using control::identification::Identification;
using control::identification::identify_run;
using control::identification::RunRefused;

Identification identify_csv(const std::string& text, const sim::RigConfig& rig) {
  std::istringstream csv(text);
  return identify_run(analyze::read_telemetry_run(csv), test::identify_options_for(rig));
}

// The PI of the paper (with the experiments' 5 µm integral band) stepping 10 mm on the rig:
// overshoot in % of the step and the last exit from the ±2 % band.
control::StepMetrics rig_step(sim::RigConfig config, double position_m, double load_kg) {
  config.valve = sim::ValveKind::servo;
  config.load_kg = load_kg;
  config.initial_position_m = position_m;
  sim::Rig rig(config);
  control::PiController pi({.integral_dead_band_m = 5e-6});
  const double target = position_m + 0.010;
  double peak = position_m, settling = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double y = rig.read().encoder_m.value;
    peak = std::max(peak, y);
    if (std::abs(y - target) > 0.02 * 0.010) settling = (k + 1) * 1e-3;
    rig.set_valve_command(pi.update(target, y));
    rig.advance(1e-3);
  }
  return {std::max(0.0, (peak - target) / 0.010 * 100.0), 0.0, settling};
}

// Every check the brief of the identification asks for, on one run.
void expect_recovered(const sim::RigConfig& rig, const test::ExcitationRun& run, const std::string& name) {
  SCOPED_TRACE(name);
  const Identification id = identify_csv(test::excitation_csv(rig, run), rig);
  const sim::Cylinder cylinder(rig.cylinder, rig.supply);
  const sim::SmallSignalPlant truth = sim::linearize(cylinder, run.position_m, run.load_kg);
  const sim::LocalParameters local = cylinder.local_parameters(run.position_m, run.load_kg);
  std::printf("%-22s b0 %7.0f ± %4.0f (rig %7.0f, %+5.2f %%)  b1 %6.1f ± %4.1f (rig %6.1f, %+5.2f %%)  "
              "k01 %6.1f ± %3.1f (rig %6.1f, %+5.2f %%)  m %5.3f (rig %5.3f, %+5.2f %%)  σ %6.1f (rig %6.1f, "
              "%+5.2f %%)  τ %.2f ms  F %.3f  residual lags out %d\n",
              name.c_str(), id.plant.b0.value, id.plant.b0.std_dev, truth.b0, 100 * (id.plant.b0.value / truth.b0 - 1),
              id.plant.b1.value, id.plant.b1.std_dev, truth.b1, 100 * (id.plant.b1.value / truth.b1 - 1),
              id.plant.k01.value, id.plant.k01.std_dev, truth.k01_mm_per_s,
              100 * (id.plant.k01.value / truth.k01_mm_per_s - 1), id.motion.mass_kg.value, local.mass_kg,
              100 * (id.motion.mass_kg.value / local.mass_kg - 1), id.motion.damping_n_s_per_m.value,
              local.damping_n_s_per_m, 100 * (id.motion.damping_n_s_per_m.value / local.damping_n_s_per_m - 1),
              id.plant.delay_s * 1e3, id.fit_index, id.residuals.outside);
  EXPECT_NEAR(id.plant.b0.value / truth.b0, 1.0, 0.05);
  EXPECT_NEAR(id.plant.b1.value / truth.b1, 1.0, 0.05);
  EXPECT_NEAR(id.plant.k01.value / truth.k01_mm_per_s, 1.0, 0.05);
  EXPECT_NEAR(id.motion.mass_kg.value / local.mass_kg, 1.0, 0.10);
  EXPECT_NEAR(id.motion.damping_n_s_per_m.value / local.damping_n_s_per_m, 1.0, 0.10);
  EXPECT_GE(id.fit_index, 0.85);
  EXPECT_NEAR(id.kp_per_m, run.kp_per_m, 1e-6 * run.kp_per_m);

  const control::StepMetrics predicted = control::step_metrics(id.plant.plant(), {85.0, 460.0});
  const control::StepMetrics simulated = rig_step(rig, run.position_m, run.load_kg);
  std::printf("%-22s PI step: overshoot %.1f %% predicted, %.1f %% on the rig; settling %.3f s predicted, %.3f s\n",
              "", predicted.overshoot_pct, simulated.overshoot_pct, predicted.settling_s, simulated.settling_s);
  EXPECT_NEAR(predicted.overshoot_pct, simulated.overshoot_pct, 3.0);
  EXPECT_NEAR(predicted.settling_s / simulated.settling_s, 1.0, 0.10);
}

TEST(Identify, RecoversThePlantAtThePapersNineWorkingPoints) {
  const sim::RigConfig rig;
  std::uint64_t seed = 11;
  for (double position : {0.050, 0.150, 0.250}) {
    for (double load : {0.0, 3.0, 6.0}) {
      test::ExcitationRun run{.position_m = position, .load_kg = load};
      run.excitation.seed = ++seed;
      expect_recovered(rig, run, std::to_string(int(position * 1e3)) + " mm " + std::to_string(int(load)) + " kg");
    }
  }
}

// A larger bore and rod on shorter hoses, a higher supply and more seal friction than the paper's.
TEST(Identify, RecoversThePlantOfALargerStifferRig) {
  sim::RigConfig rig;
  rig.cylinder.geometry = {.stroke_m = 0.304, .bore_m = 0.032, .rod_m = 0.018, .dead_length_m = 0.040};
  rig.supply = {.supply_pressure_pa = 40e5, .pump_flow_m3_per_s = 8.0 / 60000};
  rig.cylinder.static_friction_n = rig.cylinder.coulomb_friction_n = 4.0;
  test::ExcitationRun run{.position_m = 0.100, .load_kg = 3.0};
  run.excitation.seed = 101;
  expect_recovered(rig, run, "large bore, 40 bar");
}

// A 10 kg load (past the tables, so the mass is extrapolated) and a 120 Hz valve.
TEST(Identify, RecoversThePlantOfAHeavierRigWithASlowerValve) {
  sim::RigConfig rig;
  rig.servo_valve = {.bandwidth_hz = 120.0, .damping_ratio = 0.8};
  test::ExcitationRun run{.position_m = 0.200, .load_kg = 10.0};
  run.excitation.seed = 202;
  expect_recovered(rig, run, "10 kg, 120 Hz valve");
}

}  // namespace
}  // namespace hsa

namespace hsa {
namespace {

std::string run_csv(const test::ExcitationRun& run) { return test::excitation_csv(sim::RigConfig{}, run); }

void expect_refused(const std::string& csv, const std::string& words) {
  try {
    (void)identify_csv(csv, sim::RigConfig{});
    ADD_FAILURE() << "not refused; expected: " << words;
  } catch (const RunRefused& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(Identify, RefusesARunTooShort) { expect_refused(run_csv({.duration_s = 5.0}), "record at least"); }

TEST(Identify, RefusesTooLittleExcitation) {
  test::ExcitationRun run;
  run.excitation.amplitude = 20e-6;
  expect_refused(run_csv(run), "raise the excitation amplitude");
}

TEST(Identify, RefusesASaturatedValve) {
  test::ExcitationRun run{.kp_per_m = 400.0};
  run.excitation.amplitude = 5e-3;
  expect_refused(run_csv(run), "saturated");
}

// The axis fell into FAULT for one sample: the loop was not closed as the model assumes.
TEST(Identify, RefusesARunWithAFault) {
  std::string csv = run_csv({});
  const std::size_t row = csv.find('\n', csv.size() / 2) + 1;
  const std::size_t state = csv.find(',', csv.find(',', row) + 1) + 1;  // third column
  csv[state] = '3';
  expect_refused(csv, "not enabled");
}

}  // namespace
}  // namespace hsa
