// The sim plugin's reader of the rig (drivers/sim/rig_settings.hpp): the papers' rig by default,
// each [rig] group landing in its part of sim::RigConfig, and every value out of its bounds or
// inconsistent with another refused at its key, with its unit.
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include <toml++/toml.h>

#include "drivers/config_error.hpp"
#include "drivers/sim/rig_settings.hpp"

namespace hsa::io::sim_plugin {
namespace {

// Parsed as if from a file, so that messages carry file:line:column.
sim::RigConfig read(const std::string& text) {
  const toml::table table = toml::parse(text, std::string_view("rig.toml"));
  return read_rig_config(TableReader::of(table));
}

std::string refusal(const std::string& text) {
  try {
    (void)read(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << text;
  return {};
}

TEST(SimRigSettings, NoSettingsAndAnEmptyRigAreThePapersRig) {
  EXPECT_EQ(read(""), sim::RigConfig{});
  EXPECT_EQ(read("[rig]\n[rig.cylinder]\n[rig.dynamics]\n[rig.lvdt]\n"), sim::RigConfig{});
}

TEST(SimRigSettings, EachGroupLandsInItsPartOfTheRig) {
  const sim::RigConfig c = read(R"(
valve = "proportional"
load_kg = 6
initial_position_m = 0.3
seed = 9
step_s = 5e-5
[rig.cylinder]
stroke_m = 0.4
bore_m = 0.032
rod_m = 0.016
dead_length_m = 0.05
gravity_m_per_s2 = 0
static_friction_n = 5
coulomb_friction_n = 4
stick_velocity_m_per_s = 2e-4
null_leakage_m3_per_s = 1e-5
[rig.dynamics]
moving_mass_kg = 4.5
viscous_damping_n_s_per_m = 250
bulk_modulus_pa = 1.2e9
flow_coefficient_m3_per_s_per_sqrt_pa = 5e-8
[rig.supply]
supply_pressure_pa = 70e5
pump_flow_m3_per_s = 2e-4
[rig.servo_valve]
bandwidth_hz = 120
damping_ratio = 0.9
[rig.proportional_valve]
current_delay_s = 1e-4
current_error_max_a = 1e-3
current_max_a = 2.5
hysteresis_width_a = 0.2
magnetic_lag_s = 1e-3
force_constant_n_per_a = 20
moving_mass_kg = 0.08
natural_frequency_hz = 45
damping_ratio = 0.4
coulomb_friction_n = 0.1
stroke_min_m = -2e-3
stroke_max_m = 1.5e-3
opening_span_m = 1e-3
fail_safe_closed_m = -1.5e-3
[rig.sensors]
encoder_resolution_m = 5e-6
pressure_noise_std_pa = 1e3
[rig.lvdt]
bandwidth_hz = 800
gain_v_per_m = 2000
scale_factor_error = 0.01
bias_m = 1e-5
output_limit_v = 5
excitation_hz = 4000
noise_density_m_per_sqrt_hz = 1e-8
adc_rate_hz = 100e3
anti_aliasing_hz = 1500
anti_aliasing_order = 2
)");
  sim::RigConfig e;
  e.valve = sim::ValveKind::proportional;
  e.load_kg = 6.0;
  e.initial_position_m = 0.3;
  e.seed = 9;
  e.step_s = 5e-5;
  e.cylinder.geometry = {.stroke_m = 0.4, .bore_m = 0.032, .rod_m = 0.016, .dead_length_m = 0.05};
  e.cylinder.gravity_m_per_s2 = 0.0;
  e.cylinder.static_friction_n = 5.0;
  e.cylinder.coulomb_friction_n = 4.0;
  e.cylinder.stick_velocity_m_per_s = 2e-4;
  e.cylinder.null_leakage_m3_per_s = 1e-5;
  e.cylinder.dynamics = {4.5, 250.0, 1.2e9, 5e-8};
  e.supply = {70e5, 2e-4};
  e.servo_valve = {120.0, 0.9};
  sim::ProportionalValveParameters& p = e.proportional_valve;
  p.current_delay_s = 1e-4;
  p.current_error_max_a = 1e-3;
  p.current_max_a = 2.5;
  p.hysteresis_width_a = 0.2;
  p.magnetic_lag_s = 1e-3;
  p.force_constant_n_per_a = 20.0;
  p.moving_mass_kg = 0.08;
  p.natural_frequency_hz = 45.0;
  p.damping_ratio = 0.4;
  p.coulomb_friction_n = 0.1;
  p.stroke_min_m = -2e-3;
  p.stroke_max_m = 1.5e-3;
  p.opening_span_m = 1e-3;
  p.fail_safe_closed_m = -1.5e-3;
  e.sensors.encoder_resolution_m = 5e-6;
  e.sensors.pressure_noise_std_pa = 1e3;
  sim::LvdtParameters& l = e.sensors.lvdt;
  l.bandwidth_hz = 800.0;
  l.gain_v_per_m = 2000.0;
  l.scale_factor_error = 0.01;
  l.bias_m = 1e-5;
  l.output_limit_v = 5.0;
  l.excitation_hz = 4000.0;
  l.noise_density_m_per_sqrt_hz = 1e-8;
  l.adc_rate_hz = 100e3;
  l.anti_aliasing_hz = 1500.0;
  l.anti_aliasing_order = 2;
  EXPECT_EQ(c, e);
  EXPECT_NO_THROW(sim::Rig{c});  // and the rig takes it
}

TEST(SimRigSettings, ValuesOutOfBoundsAreRefusedWithTheirUnit) {
  EXPECT_EQ(refusal("[rig.cylinder]\nbore_m = 25\n"),
            "rig.toml:2:10: rig.cylinder.bore_m: expected a finite number in [0.005, 0.5] m, got 25");
  EXPECT_EQ(refusal("[rig.supply]\nsupply_pressure_pa = 25\n"),
            "rig.toml:2:22: rig.supply.supply_pressure_pa: expected a finite number in [100000, 40000000] Pa, got 25");
  EXPECT_EQ(refusal("[rig.dynamics]\nbulk_modulus_pa = 1.5e10\n"),
            "rig.toml:2:19: rig.dynamics.bulk_modulus_pa: expected a finite number in [1000000, 3000000000] Pa, "
            "got 1.5e+10");
  EXPECT_EQ(refusal("[rig.servo_valve]\nbandwidth_hz = 0\n"),
            "rig.toml:2:16: rig.servo_valve.bandwidth_hz: expected a finite number in [1, 1000] Hz, got 0");
  EXPECT_EQ(refusal("[rig.servo_valve]\ndamping_ratio = \"high\"\n"),
            "rig.toml:2:17: rig.servo_valve.damping_ratio: expected a finite number in [0.05, 5] (dimensionless), "
            "got \"high\"");
  EXPECT_EQ(refusal("[rig.proportional_valve]\nstroke_min_m = 0\n"),
            "rig.toml:2:16: rig.proportional_valve.stroke_min_m: expected a finite number in [-0.05, 0) m, got 0");
  EXPECT_EQ(refusal("[rig.cylinder]\nnull_leakage_m3_per_s = 0\n"),
            "rig.toml:2:25: rig.cylinder.null_leakage_m3_per_s: expected a finite number in (0, 0.0001] m³/s, got 0");
  EXPECT_EQ(refusal("[rig.lvdt]\nanti_aliasing_order = 3\n"),
            "rig.toml:2:23: rig.lvdt.anti_aliasing_order: expected 0 or an even integer in [2, 8], got 3");
  EXPECT_EQ(refusal("load_kg = -1\n"), "rig.toml:1:11: load_kg: expected a finite number >= 0 kg, got -1");
  EXPECT_EQ(refusal("step_s = 0.01\n"), "rig.toml:1:10: step_s: expected a finite number in (0, 0.001] s, got 0.01");
}

TEST(SimRigSettings, UnknownGroupsAndKeysAreRefused) {
  EXPECT_EQ(refusal("[rig.cylnder]\nbore_m = 0.03\n"),
            "rig.toml:1:6: rig.cylnder: unknown key, expected one of: cylinder, dynamics, supply, servo_valve, "
            "proportional_valve, sensors, lvdt");
  EXPECT_EQ(refusal("[rig.cylinder]\nbore_mm = 30\n"),
            "rig.toml:2:1: rig.cylinder.bore_mm: unknown key, expected one of: stroke_m, bore_m, rod_m, "
            "dead_length_m, gravity_m_per_s2, static_friction_n, coulomb_friction_n, stick_velocity_m_per_s, "
            "null_leakage_m3_per_s");
}

TEST(SimRigSettings, InconsistentCombinationsAreRefusedAtTheKeyWritten) {
  // Rod as wide as the bore: at whichever of the two the configuration wrote.
  EXPECT_EQ(refusal("[rig.cylinder]\nrod_m = 0.025\n"),
            "rig.toml:2:9: rig.cylinder.rod_m: expected a rod diameter below the bore, rig.cylinder.bore_m = 0.025 m, "
            "got 0.025");
  EXPECT_EQ(refusal("[rig.cylinder]\nbore_m = 0.01\n"),
            "rig.toml:2:10: rig.cylinder.bore_m: expected a bore wider than the rod, rig.cylinder.rod_m = 0.012 m, "
            "got 0.01");
  EXPECT_EQ(refusal("[rig.cylinder]\ncoulomb_friction_n = 3\n"),
            "rig.toml:2:22: rig.cylinder.coulomb_friction_n: expected at most the static friction, "
            "rig.cylinder.static_friction_n = 2 N, got 3");
  // A dead band that leaves the regulator no current to open the valve fully: the spring needs
  // 9870 N/m · 3.75 mm / 18 N/A = 2.056 A at full opening, plus the 1 A band, over the 3 A maximum.
  EXPECT_EQ(refusal("[rig.proportional_valve]\nhysteresis_width_a = 1\n"),
            "rig.toml:2:22: rig.proportional_valve.hysteresis_width_a: expected a valve the current can open "
            "fully: spring force at full opening / force constant + dead band = 3.056167584 A must be at most "
            "rig.proportional_valve.current_max_a = 3 A, got 1");
  // Refused at the parameter written even when the clash is with defaults it does not name: a
  // weaker solenoid needs 2.056 A · 18/9 = 4.11 A, plus the 0.3 A band, to open fully.
  EXPECT_EQ(refusal("[rig.proportional_valve]\nforce_constant_n_per_a = 9\n"),
            "rig.toml:2:26: rig.proportional_valve.force_constant_n_per_a: expected a valve the current can "
            "open fully: spring force at full opening / force constant + dead band = 4.412335167 A must be at most "
            "rig.proportional_valve.current_max_a = 3 A, got 9");
  EXPECT_EQ(refusal("[rig.proportional_valve]\nopening_span_m = 2e-3\n"),
            "rig.toml:2:18: rig.proportional_valve.opening_span_m: expected at most the end stop, "
            "rig.proportional_valve.stroke_max_m = 0.00125 m, got 0.002");
  EXPECT_EQ(refusal("[rig.proportional_valve]\nfail_safe_closed_m = -1e-3\n"),
            "rig.toml:2:22: rig.proportional_valve.fail_safe_closed_m: expected below the full negative opening, "
            "-rig.proportional_valve.opening_span_m = 0.00125 m, got -0.001");
  EXPECT_EQ(refusal("[rig.proportional_valve]\nstroke_min_m = -1.5e-3\n"),
            "rig.toml:2:16: rig.proportional_valve.stroke_min_m: expected at most the fail-safe edge, "
            "rig.proportional_valve.fail_safe_closed_m = -0.001875 m, got -0.0015");
  EXPECT_EQ(refusal("[rig.lvdt]\nadc_rate_hz = 5000\n"),
            "rig.toml:2:15: rig.lvdt.adc_rate_hz: expected an anti-aliasing cut-off below a quarter of the ADC rate, "
            "rig.lvdt.anti_aliasing_hz = 2000 Hz and rig.lvdt.adc_rate_hz = 5000 Hz, got 5000");
  EXPECT_EQ(refusal("[rig.proportional_valve]\ncurrent_delay_s = 5e-5\n"),
            "rig.toml:2:19: rig.proportional_valve.current_delay_s: expected at least one step, step_s = 0.0001 s, "
            "got 5e-05");
  // The initial position must lie in a shortened stroke.
  EXPECT_EQ(refusal("[rig.cylinder]\nstroke_m = 0.1\n"),
            "rig.toml:2:12: rig.cylinder.stroke_m: expected a stroke that holds the initial position, "
            "initial_position_m = 0.15 m, got 0.1");
  EXPECT_EQ(refusal("initial_position_m = 0.35\n"),
            "rig.toml:1:22: initial_position_m: expected a finite number in [0, 0.304] m, within the stroke "
            "rig.cylinder.stroke_m = 0.304 m, got 0.35");
}

}  // namespace
}  // namespace hsa::io::sim_plugin
