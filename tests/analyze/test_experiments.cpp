// The papers' experiments on the simulated rig, with the papers' limits: Puglisi et al.'s in
// direct mode (servo-valve), Canuto et al.'s valve experiments on the proportional valve under the
// tuned valve loop. The limits are the papers' requirements: they are not to be widened to make a
// run pass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "sim/proportional_valve.hpp"
#include "tools/hsa_analyze/experiments.hpp"
#include "tools/hsa_analyze/valve_experiments.hpp"

namespace hsa::analyze {
namespace {

// Exp. 1 once for all nine cases: the spread test needs them all and they take a few seconds.
const std::vector<StepMetrics>& step_cases() {
  static const std::vector<StepMetrics> cases = [] {
    std::vector<StepMetrics> c;
    for (double position : kStepPositionsM)
      for (double load : kLoadsKg) c.push_back(run_step(position, load));
    return c;
  }();
  return cases;
}

TEST(Experiments, StepOvershootSettlingAndNoOscillationInEachCase) {
  for (const StepMetrics& m : step_cases()) {
    SCOPED_TRACE(testing::Message() << m.position_m * 1e3 << " mm, " << m.load_kg << " kg");
    EXPECT_GE(m.overshoot_pct, 10.0);
    EXPECT_LE(m.overshoot_pct, 30.0);
    EXPECT_LE(m.settling_s, 0.6);
    EXPECT_FALSE(m.oscillating) << "at rest " << m.rest_peak_to_peak_counts << " counts peak to peak";
    EXPECT_LE(std::abs(m.rest_error_m), kIntegralDeadBandM + 1e-6) << "rests outside the integral's dead band";
  }
}

TEST(Experiments, StepSpreadAcrossTheNineCases) {
  const StepSpread s = step_spread(step_cases());
  EXPECT_LE(s.overshoot_spread_pts, 5.0);
  EXPECT_LE(s.settling_spread, 0.10);
}

TEST(Experiments, SineTrackingWithinOneMillimetreUpToHalfARadianPerSecond) {
  // Two periods each (the first is the start-up and is not scored): 0.1 rad/s is 126 s of rig time.
  for (double omega : {0.1, 0.2, 0.5}) {
    for (double load : kLoadsKg) {
      const SineMetrics m = run_sine(omega, load, 2);
      EXPECT_LE(m.max_error_m, 1e-3) << omega << " rad/s, " << load << " kg";
    }
  }
}

// Exp. 3 with the weight handled as a hand does it (see kHandLoadChangeS), and a hand twice as
// quick: stable, and the peak error within the 2 mm.
TEST(Experiments, LoadDisturbanceByHandDuringSineStaysStableWithinTwoMillimetres) {
  for (double change_s : {kHandLoadChangeS, kHandLoadChangeS / 2}) {
    const DisturbanceMetrics m = run_disturbance(0.0, 3.0, {}, change_s);
    SCOPED_TRACE(testing::Message() << "weight on/off over " << change_s << " s");
    EXPECT_TRUE(m.stable) << "final " << m.final_error_m << " m, baseline " << m.baseline_error_m << " m";
    EXPECT_LE(m.peak_error_m, 2e-3);
  }
}

// Dropped in zero time the weight's release throws the light rod up by about ΔF/k_h (1.3 mm) plus
// its overshoot: more than 2 mm, which no gain of the paper's PI could stop. The loop must still
// come back to its earlier tracking.
TEST(Experiments, LoadStepDuringSineStaysStable) {
  const DisturbanceMetrics m = run_disturbance(0.0, 3.0, {}, 0.0);
  EXPECT_TRUE(m.stable) << "final " << m.final_error_m << " m, baseline " << m.baseline_error_m << " m";
  EXPECT_GT(m.removed_peak_error_m, m.baseline_error_m);  // the step is felt
}

TEST(Experiments, POnlyLeavesASteadyErrorUnderGravityThatThePiRemoves) {
  control::PiParams p_only;
  p_only.ki = 0.0;
  const HoldMetrics p_light = run_hold(0.150, 0.0, {.pi = p_only});
  const HoldMetrics p = run_hold(0.150, 6.0, {.pi = p_only});
  const HoldMetrics pi = run_hold(0.150, 6.0, {});
  EXPECT_GT(std::abs(p.mean_error_m), std::abs(p_light.mean_error_m)) << "the P error does not grow with the load";
  EXPECT_GT(std::abs(p.mean_error_m), std::abs(pi.mean_error_m));
  // The PI leaves at most its integral dead band (kIntegralDeadBandM), and a count of quantization.
  EXPECT_LE(std::abs(pi.mean_error_m), kIntegralDeadBandM + 1e-6);
}

// ---- Canuto et al. (2014) section 4: the valve loop on the simulated proportional valve ----

// The preset's bias must be the one the simulated valve holds hydraulic zero with; the tuning and
// every number below assume it.
TEST(ValveExperiments, PresetBiasIsTheSimulatedValvesBias) {
  const sim::ProportionalValve valve({}, 1e-4);
  EXPECT_NEAR(control::simulated_proportional_valve_law().bias_current_a, valve.bias_current(), 1e-3);
}

TEST(ValveExperiments, SeventyPercentTriangleDelayWithinFiveMilliseconds) {
  const ValveTriangleMetrics m = run_valve_triangle(0.70, 10.0);
  EXPECT_LE(m.delay_s, 5e-3);
  // A delay of 0 would mean the fit failed rather than a perfect valve: the loop has at least its
  // sample, the 0.2 ms current delay and the magnetic lag.
  EXPECT_GT(m.delay_s, 0.5e-3);
}

TEST(ValveExperiments, FivePercentSineWithinThreeDecibelsUpTo100Hz) {
  std::vector<ValveSineMetrics> sweep;
  for (double f : kValveSineFrequenciesHz) {
    if (f > 100.0) break;
    sweep.push_back(run_valve_sine(0.05, f));
    EXPECT_LE(std::abs(sweep.back().gain_db), 3.0) << f << " Hz";
  }
  EXPECT_EQ(sweep.back().frequency_hz, 100.0);
}

// The sweep must be able to fail: well past the loop's bandwidth the gain has dropped.
TEST(ValveExperiments, FivePercentSineFallsOffAboveTheBandwidth) {
  EXPECT_LT(run_valve_sine(0.05, 300.0).gain_db, -3.0);
}

// Eq 9's residual and the slew rate are printed, not limited (the paper misses both of its own
// requirements); these only check that the measurements mean something.
TEST(ValveExperiments, SquareWaveSlewRateAndTriangleResidualAreMeasured) {
  const ValveSquareMetrics sq = run_valve_square(0.50, 10.0);
  EXPECT_GT(sq.slew_rate_m_s, 0.0);
  EXPECT_TRUE(std::isfinite(sq.slew_rate_m_s));
  const ValveTriangleMetrics tri = run_valve_triangle(0.70, 10.0);
  EXPECT_GT(tri.residual_max_m, tri.residual_rms_m);
  EXPECT_LT(tri.residual_max_m, 0.1 * 0.70 * kValveStrokeM);  // a tenth of the amplitude: it tracks
}

// ---- Cascade mode: the PI over the valve loop, on the proportional valve ----

TEST(CascadeExperiments, StepOvershootSettlingRestAndSpreadInTheNineCases) {
  std::vector<StepMetrics> cases;
  for (double position : kStepPositionsM) {
    for (double load : kLoadsKg) {
      cases.push_back(run_step(position, load, {.drive = Drive::cascade}));
      const StepMetrics& m = cases.back();
      SCOPED_TRACE(testing::Message() << position * 1e3 << " mm, " << load << " kg");
      EXPECT_GE(m.overshoot_pct, 10.0);
      EXPECT_LE(m.overshoot_pct, 30.0);
      EXPECT_LE(m.settling_s, 0.6);
      EXPECT_FALSE(m.oscillating) << "at rest " << m.rest_peak_to_peak_counts << " counts peak to peak";
      EXPECT_LE(std::abs(m.rest_error_m), kIntegralDeadBandM + 1e-6) << "rests outside the integral's dead band";
    }
  }
  const StepSpread s = step_spread(cases);
  EXPECT_LE(s.overshoot_spread_pts, 5.0);
  EXPECT_LE(s.settling_spread, 0.10);
}

TEST(CascadeExperiments, SineTrackingWithinOneMillimetreAtHalfARadianPerSecond) {
  EXPECT_LE(run_sine(0.5, 3.0, 2, {.drive = Drive::cascade}).max_error_m, 1e-3);
}

// Why the experiments' PI parks its integrator near the setpoint (kIntegralDeadBandM): with the
// paper's bare PI the rod hunts in stick-slip in both drives, still 10 s after the step. If this
// fails, the rig no longer hunts and the band is no longer needed.
TEST(Experiments, BarePiHuntsInStickSlipInBothDrives) {
  for (Drive drive : {Drive::direct, Drive::cascade}) {
    int hunting = 0;
    for (double position : kStepPositionsM) {
      for (double load : kLoadsKg) {
        analyze::Setup bare{.drive = drive};
        bare.pi.integral_dead_band_m = 0.0;
        if (run_step(position, load, bare).oscillating) ++hunting;
      }
    }
    EXPECT_GE(hunting, 6) << drive_name(drive) << ": only " << hunting << " of 9 cases hunt";
  }
}

// The valve loop must not need the LVDT's noise to get through the magnetic dead band. Without
// the dither, a noise-free LVDT lets the spool stick in the band and the cascade hunts at about
// 4 Hz with errors near ±0.3 mm (the noise had been doing the dither's job); with the preset's
// dither the same run holds within a few tens of µm.
TEST(CascadeExperiments, DitherKeepsANoiseFreeLvdtFromHunting) {
  control::ValveLawParams no_dither = control::simulated_proportional_valve_law();
  no_dither.dither_amplitude_a = 0.0;
  for (double load : kLoadsKg) {
    SCOPED_TRACE(testing::Message() << load << " kg");
    const HoldMetrics dithered = run_hold(0.150, load, {.drive = Drive::cascade, .noiseless_lvdt = true});
    const HoldMetrics bare =
        run_hold(0.150, load, {.drive = Drive::cascade, .valve = no_dither, .noiseless_lvdt = true});
    EXPECT_GT(bare.max_abs_error_m, 0.2e-3) << "the dead band no longer hunts without dither: revisit the preset";
    EXPECT_LT(dithered.max_abs_error_m, 50e-6);
  }
}

// ---- --csv ----

TEST(Trace, CsvHasAHeaderAndOneRowPerRecordedSample) {
  Trace trace;
  run_valve_triangle(0.70, 10.0, control::simulated_proportional_valve_law(), {}, &trace);
  const std::string path = testing::TempDir() + "hsa_trace_test.csv";
  trace.write_csv(path);
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "case,t_s,reference_m,spool_m,error_m,command_a,current_a,opening");
  std::size_t rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_EQ(rows, trace.rows());
  EXPECT_GT(rows, 1000u);
  std::remove(path.c_str());
}

TEST(Trace, RejectsMismatchedColumns) {
  Trace trace;
  trace.begin("a", {"t", "x"});
  EXPECT_THROW(trace.add({1.0}), std::logic_error);
  EXPECT_THROW(trace.begin("b", {"t"}), std::logic_error);
}

}  // namespace
}  // namespace hsa::analyze
