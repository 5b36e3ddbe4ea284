// `hsa-analyze identify --set`'s method on runs made on the simulated rig (identification_run.hpp,
// read back through the CSV path of a recorded run): the nominal plant of eq 49 (Puglisi et al.
// 2015) over the paper's nine step cases, the PI's margins on every plant of the set as written to
// and read from the plant-set file, and the axis's capability against the rig's own physics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "control/identification/identify_set.hpp"
#include "control/loop_analysis.hpp"
#include "plant_set/plant_set_file.hpp"
#include "sim/cylinder.hpp"
#include "tests/analyze/identification_run.hpp"
#include "tools/hsa_analyze/telemetry_run.hpp"

namespace hsa {
namespace {

using control::identification::AxisCapability;
using control::identification::IdentifyOptions;
using control::identification::NamedRun;
using control::identification::SupplyRating;

IdentifyOptions options_for(const sim::RigConfig& rig) {
  IdentifyOptions o;
  o.hydraulics.piston_area_m2 = rig.cylinder.geometry.piston_area();
  o.hydraulics.area_ratio = rig.cylinder.geometry.area_ratio();
  return o;
}

SupplyRating rating_of(const sim::RigConfig& rig) {
  return {.supply_pressure_pa = rig.supply.supply_pressure_pa, .pump_flow_m3_per_s = rig.supply.pump_flow_m3_per_s};
}

NamedRun simulated_run(const sim::RigConfig& rig, const test::ExcitationRun& run, const std::string& name) {
  std::istringstream csv(test::excitation_csv(rig, run));
  return {name, run.load_kg, analyze::read_telemetry_run(csv)};
}

// The rig's steady rod speed with the valve held at `opening` (±1), the rod held at `position_m`
// so the chambers' volumes stay those of the working point: the rig's own orifice, pump, leakage,
// damping and friction, integrated until nothing changes.
double rig_top_speed(const sim::RigConfig& config, double position_m, double load_kg, double opening) {
  const sim::Cylinder cylinder(config.cylinder, config.supply);
  sim::CylinderState s = cylinder.rest_state(position_m, load_kg);
  for (int k = 0; k < 20000; ++k) {
    cylinder.step(s, opening, load_kg, true, 1e-4);
    s.position_m = position_m;
  }
  return std::abs(s.velocity_m_per_s);
}

// The rig's largest rod acceleration when the valve command jumps from closed to `opening` (±1)
// at rest: the whole simulated rig, servo-valve included, over the first 0.1 s.
double rig_peak_acceleration(sim::RigConfig config, double position_m, double load_kg, double opening) {
  config.valve = sim::ValveKind::servo;
  config.load_kg = load_kg;
  config.initial_position_m = position_m;
  sim::Rig rig(config);
  rig.set_valve_command(opening);
  double peak = 0.0, v = rig.cylinder_state().velocity_m_per_s;
  for (int k = 0; k < 1000; ++k) {
    rig.step();
    const double now = rig.cylinder_state().velocity_m_per_s;
    peak = std::max(peak, std::abs(now - v) / config.step_s);
    v = now;
  }
  return peak;
}

void expect_capability(const sim::RigConfig& rig, const test::ExcitationRun& run, const std::string& name) {
  SCOPED_TRACE(name);
  const auto s = control::identification::identify_set({simulated_run(rig, run, name)}, options_for(rig), rating_of(rig));
  const AxisCapability& c = s.set.capability;
  const double v_ext = rig_top_speed(rig, run.position_m, run.load_kg, 1.0);
  const double v_ret = rig_top_speed(rig, run.position_m, run.load_kg, -1.0);
  const double a_ext = rig_peak_acceleration(rig, run.position_m, run.load_kg, 1.0);
  const double a_ret = rig_peak_acceleration(rig, run.position_m, run.load_kg, -1.0);
  std::printf("%-26s extend: speed %.4f m/s (%s; rig %.4f, %+5.1f %%), accel %6.2f m/s² (%s; rig %6.2f, %+5.1f %%)\n",
              name.c_str(), c.extend.max_speed_m_s, c.extend.speed_pump_limited ? "pump" : "valve", v_ext,
              100 * (c.extend.max_speed_m_s / v_ext - 1), c.extend.max_acceleration_m_s2,
              c.extend.acceleration_force_limited ? "force" : "mode", a_ext,
              100 * (c.extend.max_acceleration_m_s2 / a_ext - 1));
  std::printf("%-26s retract: speed %.4f m/s (%s; rig %.4f, %+5.1f %%), accel %6.2f m/s² (%s; rig %6.2f, %+5.1f %%)\n",
              "", c.retract.max_speed_m_s, c.retract.speed_pump_limited ? "pump" : "valve", v_ret,
              100 * (c.retract.max_speed_m_s / v_ret - 1), c.retract.max_acceleration_m_s2,
              c.retract.acceleration_force_limited ? "force" : "mode", a_ret,
              100 * (c.retract.max_acceleration_m_s2 / a_ret - 1));
  EXPECT_NEAR(c.extend.max_speed_m_s / v_ext, 1.0, 0.10);
  EXPECT_NEAR(c.retract.max_speed_m_s / v_ret, 1.0, 0.10);
  EXPECT_NEAR(c.extend.max_acceleration_m_s2 / a_ext, 1.0, 0.10);
  EXPECT_NEAR(c.retract.max_acceleration_m_s2 / a_ret, 1.0, 0.10);
  EXPECT_DOUBLE_EQ(c.extend.speed_limit_m_s, 0.7 * c.extend.max_speed_m_s);
  EXPECT_DOUBLE_EQ(c.retract.acceleration_limit_m_s2, 0.7 * c.retract.max_acceleration_m_s2);
}

TEST(IdentifySet, CapabilityMatchesThePapersRigAt0And6Kg) {
  const sim::RigConfig rig;
  expect_capability(rig, {.position_m = 0.150, .load_kg = 0.0, .duration_s = 15.0}, "150 mm 0 kg");
  expect_capability(rig, {.position_m = 0.150, .load_kg = 6.0, .duration_s = 15.0}, "150 mm 6 kg");
}

// The larger rig of test_identify.cpp: 32 mm bore, 40 bar, 8 L/min.
TEST(IdentifySet, CapabilityMatchesALargerBore) {
  sim::RigConfig rig;
  rig.cylinder.geometry = {.stroke_m = 0.304, .bore_m = 0.032, .rod_m = 0.018, .dead_length_m = 0.040};
  rig.supply = {.supply_pressure_pa = 40e5, .pump_flow_m3_per_s = 8.0 / 60000};
  rig.cylinder.static_friction_n = rig.cylinder.coulomb_friction_n = 4.0;
  expect_capability(rig, {.position_m = 0.100, .load_kg = 3.0, .duration_s = 15.0}, "32 mm bore, 40 bar, 3 kg");
}

}  // namespace
}  // namespace hsa
