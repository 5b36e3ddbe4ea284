// `hsa-analyze identify-valve`: the proportional valve of Canuto et al. (2014), section 2,
// identified from a record the simulated rig makes at the valve rate in lockstep
// (tools/hsa_analyze/valve_excitation.hpp), with the rig's noise (regulator error, LVDT noise and
// ripple, anti-aliasing filter). Every parameter the record can show must come within 10 % of the
// simulated valve's, on the paper's valve and on a variant with another dead band, spring and
// current limit; records the fit cannot use are refused with what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "control/identification/identify_run.hpp"
#include "control/identification/valve_fit.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"
#include "tools/hsa_analyze/valve_record.hpp"

namespace {

using hsa::analyze::ValveExcitation;
using hsa::control::identification::Estimate;
using hsa::control::identification::fit_valve;
using hsa::control::identification::RunRefused;
using hsa::control::identification::ValveFit;
using hsa::control::identification::ValveRecord;
using hsa::sim::ProportionalValveParameters;

// What the record can show of a simulated valve, from its parameters.
struct Truth {
  double width_a, lag_s, f0_hz, zeta, gain_m_per_a, rest_m, friction_band_m, stroke_max_m, current_max_a, delay_s;
};

Truth truth_of(const ProportionalValveParameters& p) {
  const double omega = 2.0 * std::numbers::pi * p.natural_frequency_hz;
  const double k = p.moving_mass_kg * omega * omega;
  return {p.hysteresis_width_a, p.magnetic_lag_s,  p.natural_frequency_hz, p.damping_ratio,
          p.force_constant_n_per_a / k, p.stroke_min_m, p.coulomb_friction_n / k, p.stroke_max_m,
          p.current_max_a,        p.current_delay_s};
}

void expect_within(const char* name, const Estimate& e, double truth, double tolerance = 0.10) {
  std::printf("  %-22s true %12.6g  identified %12.6g ± %-10.3g (%+.2f %%)\n", name, truth, e.value, e.std_dev,
              100.0 * (e.value - truth) / truth);
  EXPECT_NEAR(e.value, truth, tolerance * std::abs(truth)) << name;
  EXPECT_TRUE(std::isfinite(e.std_dev) && e.std_dev >= 0.0) << name;
}

void expect_identified(const ValveFit& f, const Truth& t) {
  expect_within("dead band w [A]", f.width_a, t.width_a);
  expect_within("magnetic lag tau_a [s]", f.magnetic_lag_s, t.lag_s);
  expect_within("f0 [Hz]", f.natural_frequency_hz, t.f0_hz);
  expect_within("zeta", f.damping_ratio, t.zeta);
  expect_within("g = K_f/K [m/A]", f.gain_m_per_a, t.gain_m_per_a);
  expect_within("X_min [m]", f.rest_position_m, t.rest_m);
  expect_within("s_f = F_c/K [m]", f.friction_band_m, t.friction_band_m);
  ASSERT_TRUE(f.end_stop_reached);
  expect_within("X_max [m]", f.stroke_max_m, t.stroke_max_m);
  ASSERT_TRUE(f.regulator.limit_reached);
  expect_within("I_max [A]", f.regulator.current_max_a, t.current_max_a);
  EXPECT_NEAR(f.regulator.delay_s, t.delay_s, 1e-9);
  EXPECT_LE(f.regulator.error_max_a, 1.5e-3 + 1e-9);
  std::printf("  equation-error start: w %.3f A, tau_a %.3f ms, f0 %.2f Hz, zeta %.3f, g %.4g m/A, delay %.3f ms; fitted delay %.3f ms\n",
              f.equation_error.width_a, f.equation_error.magnetic_lag_s * 1e3, f.equation_error.natural_frequency_hz,
              f.equation_error.damping_ratio, f.equation_error.gain_m_per_a, f.equation_error.delay_s * 1e3,
              f.delay_s * 1e3);
  std::printf("  fit index %.2f %%, residual lags outside the 99 %% band %d of %zu\n", 100.0 * f.fit_index,
              f.residuals.outside, f.residuals.autocorrelation.size());
  EXPECT_GT(f.fit_index, 0.95);
}

TEST(IdentifyValve, PaperValveWithinTenPercent) {
  const ProportionalValveParameters valve{};
  const ValveRecord record = hsa::analyze::run_valve_excitation(ValveExcitation{}, valve);
  const ValveFit fit = fit_valve(record);
  expect_identified(fit, truth_of(valve));
  // The forces for the paper's mass are the simulated valve's, as far as f0, ζ, g and s_f are.
  const double k = valve.moving_mass_kg * std::pow(2.0 * std::numbers::pi * valve.natural_frequency_hz, 2);
  expect_within("K [N/m] at m = 0.1 kg", fit.stiffness_n_per_m, k);
  expect_within("K_f [N/A] at m = 0.1 kg", fit.force_constant_n_per_a, valve.force_constant_n_per_a);
}

// Another valve: a wider dead band, a softer spring, a lower current limit. The excitation's bias
// and amplitude are set for its stroke, as valve_excitation.hpp tells an operator to.
TEST(IdentifyValve, VariantWithinTenPercent) {
  ProportionalValveParameters valve;
  valve.hysteresis_width_a = 0.5;
  valve.natural_frequency_hz = 40.0;
  valve.current_max_a = 2.5;
  ValveExcitation excitation;
  excitation.bias_a = 0.85;
  excitation.amplitude_a = 0.55;
  const ValveRecord record = hsa::analyze::run_valve_excitation(excitation, valve, 2);
  const ValveFit fit = fit_valve(record);
  expect_identified(fit, truth_of(valve));
  const double k = valve.moving_mass_kg * std::pow(2.0 * std::numbers::pi * valve.natural_frequency_hz, 2);
  expect_within("K [N/m] at m = 0.1 kg", fit.stiffness_n_per_m, k);
  expect_within("K_f [N/A] at m = 0.1 kg", fit.force_constant_n_per_a, valve.force_constant_n_per_a);
}

// The record through the CSV the experiment writes and the command reads.
TEST(IdentifyValve, CsvRoundTrip) {
  ValveExcitation excitation;
  excitation.duration_s = 0.5;
  excitation.probe_a = 0.0;
  hsa::analyze::Trace trace;
  const ValveRecord made = hsa::analyze::run_valve_excitation(excitation, {}, 1, &trace);
  const std::string path = testing::TempDir() + "valve_excite.csv";
  trace.write_csv(path);
  std::ifstream file(path);
  const ValveRecord read = hsa::analyze::read_valve_record(file);
  ASSERT_EQ(read.spool_m.size(), made.spool_m.size());
  EXPECT_NEAR(read.period_s, made.period_s, 1e-12);
  // Trace writes 9 significant digits: the values come back to 5e-9 of their magnitude.
  const auto same = [](double a, double b) { return std::abs(a - b) <= 5e-9 * std::abs(b) + 1e-300; };
  for (std::size_t k = 0; k < made.spool_m.size(); ++k) {
    ASSERT_TRUE(same(read.command_a[k], made.command_a[k])) << k;
    ASSERT_TRUE(same(read.current_a[k], made.current_a[k])) << k;
    ASSERT_TRUE(same(read.spool_m[k], made.spool_m[k])) << k;
  }
}

std::string refusal(const ValveRecord& r) {
  try {
    (void)fit_valve(r);
  } catch (const RunRefused& e) {
    return e.what();
  }
  return "";
}

ValveRecord short_record() {
  ValveExcitation e;
  e.duration_s = 2.5;
  e.probe_a = 0.0;
  return hsa::analyze::run_valve_excitation(e);
}

TEST(IdentifyValve, RefusesTooShort) {
  ValveRecord r = short_record();
  for (auto* v : {&r.command_a, &r.current_a, &r.spool_m}) v->resize(10000);  // 1 s
  EXPECT_NE(refusal(r).find("lasts 1.000 s"), std::string::npos) << refusal(r);
}

TEST(IdentifyValve, RefusesConstantCurrent) {
  ValveExcitation e;
  e.amplitude_a = 0.0;
  e.duration_s = 2.5;
  e.probe_a = 0.0;
  const std::string why = refusal(hsa::analyze::run_valve_excitation(e));
  EXPECT_NE(why.find("cross the dead band"), std::string::npos) << why;
}

TEST(IdentifyValve, RefusesNaN) {
  ValveRecord r = short_record();
  r.spool_m[1234] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(refusal(r).find("sample 1234 is not finite"), std::string::npos) << refusal(r);
}

TEST(IdentifyValve, RefusesColumnsOfDifferentLength) {
  ValveRecord r = short_record();
  r.current_a.pop_back();
  EXPECT_NE(refusal(r).find("differ in length"), std::string::npos) << refusal(r);
}

std::string csv_refusal(const std::string& text) {
  std::istringstream in(text);
  try {
    (void)hsa::analyze::read_valve_record(in);
  } catch (const RunRefused& e) {
    return e.what();
  }
  return "";
}

TEST(IdentifyValve, CsvRefusesMissingColumnNaNAndGaps) {
  EXPECT_NE(csv_refusal("t_s,command_a,spool_m\n0.0001,1,0\n").find("no column 'current_a'"), std::string::npos);
  const std::string nan = csv_refusal("t_s,command_a,current_a,spool_m\n0.0001,1,1,0\n0.0002,1,nan,0\n");
  EXPECT_NE(nan.find("line 3, column current_a: 'nan' is not a finite number"), std::string::npos) << nan;
  const std::string gap = csv_refusal(
      "t_s,command_a,current_a,spool_m\n0.0001,1,1,0\n0.0002,1,1,0\n0.0003,1,1,0\n0.0005,1,1,0\n");
  EXPECT_NE(gap.find("line 5, column t_s"), std::string::npos) << gap;
  EXPECT_NE(csv_refusal("").find("empty"), std::string::npos);
}

}  // namespace
