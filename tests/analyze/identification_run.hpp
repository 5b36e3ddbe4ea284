// A closed-loop identification run made on the simulated rig, as `hsactl excite` will make it on
// hsad: a proportional controller at 1 kHz around a working point, a PRMS added to the setpoint,
// sensor noise on, every sample written by the CSV writer of `hsactl record`. The test then
// reads it back through `hsa-analyze identify`'s input path (tools/hsa_analyze/telemetry_run).
#pragma once

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "control/excitation_sequence.hpp"
#include "control/identification/identify_run.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"
#include "sim/rig.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace hsa::test {

struct ExcitationRun {
  double position_m = 0.150;
  double load_kg = 0.0;
  double kp_per_m = 200.0;  // 0.2 per mm: an underdamped loop, as the paper asks (section 3.1.1)
  double duration_s = 30.0;
  // ±1 mm: at 0.2 per mm the opening stays within ±0.4, the rod within the pump's 0.17 m/s, and
  // the viscous force well above the seals' 2 N.
  control::ExcitationParams excitation{.amplitude = 1e-3, .switching_time_s = 0.3, .levels = 5, .seed = 3};
};

inline constexpr double kLoopPeriodS = 1e-3;

// identify's options for a run on `rig`: its cylinder's piston area and area ratio.
inline control::identification::IdentifyOptions identify_options_for(const sim::RigConfig& rig) {
  control::identification::IdentifyOptions o;
  o.hydraulics.piston_area_m2 = rig.cylinder.geometry.piston_area();
  o.hydraulics.area_ratio = rig.cylinder.geometry.area_ratio();
  return o;
}

// The CSV of the run; `rig` starts at rest at the working point.
inline std::string excitation_csv(sim::RigConfig rig_config, const ExcitationRun& run) {
  rig_config.valve = sim::ValveKind::servo;
  rig_config.load_kg = run.load_kg;
  rig_config.initial_position_m = run.position_m;
  sim::Rig rig(rig_config);
  control::ExcitationParams params = run.excitation;
  params.sample_period_s = kLoopPeriodS;
  control::ExcitationSequence excitation(params);
  std::ostringstream csv;
  ctl::write_telemetry_csv_header(csv);
  const long samples = std::lround(run.duration_s / kLoopPeriodS);
  for (long k = 0; k < samples; ++k) {
    const sim::RigReadings r = rig.read();
    hsa::telemetry_t t{};
    t.utime = 1'000'000 + k * 1000;
    t.seq = k * 10;
    t.state = hsa::status_t::STATE_ENABLED;
    t.valve_enabled = true;
    t.setpoint_m = run.position_m + excitation.next();
    t.position_m = r.encoder_m.value;
    t.following_error_m = t.setpoint_m - t.position_m;
    t.valve_opening = std::clamp(run.kp_per_m * t.following_error_m, -1.0, 1.0);
    t.pressure_a_pa = r.pressure_a_pa.value;
    t.pressure_b_pa = r.pressure_b_pa.value;
    t.load_pressure_pa = t.pressure_a_pa - t.pressure_b_pa;
    ctl::write_telemetry_csv_row(csv, t);
    rig.set_valve_command(t.valve_opening);
    rig.advance(kLoopPeriodS);
  }
  return csv.str();
}

}  // namespace hsa::test
