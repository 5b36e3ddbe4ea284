#include "tools/hsa_analyze/valve_excitation.hpp"

#include <algorithm>
#include <cmath>

#include "control/excitation_sequence.hpp"
#include "sim/rig.hpp"

namespace hsa::analyze {

control::identification::ValveRecord run_valve_excitation(const ValveExcitation& e,
                                                          const sim::ProportionalValveParameters& valve,
                                                          std::uint64_t rig_seed, Trace* trace) {
  sim::RigConfig config;
  config.valve = sim::ValveKind::proportional;
  config.proportional_valve = valve;
  config.seed = rig_seed;
  sim::Rig rig(config);
  const double period = config.step_s;
  control::ExcitationSequence prms({.kind = control::ExcitationKind::prms,
                                    .amplitude = e.amplitude_a,
                                    .switching_time_s = e.switching_time_s,
                                    .levels = e.levels,
                                    .max_hold_switches = e.max_hold_switches,
                                    .seed = e.seed,
                                    .sample_period_s = period});
  const long excite = std::lround(e.duration_s / period);
  const long ramp = std::lround(0.1 / period);
  const long top = std::lround(0.05 / period);
  const long probe = e.probe_a > 0.0 ? 2 * ramp + top + std::lround(0.1 / period) : 0;
  const auto command = [&](long k) {
    if (k < excite) return e.bias_a + prms.next();
    const long j = k - excite;
    const double rise = e.probe_a - e.bias_a;
    if (j < ramp) return e.bias_a + rise * static_cast<double>(j) / static_cast<double>(ramp);
    if (j < ramp + top) return e.probe_a;
    if (j < 2 * ramp + top) return e.probe_a - rise * static_cast<double>(j - ramp - top) / static_cast<double>(ramp);
    return e.bias_a;
  };

  control::identification::ValveRecord r;
  r.period_s = period;
  if (trace != nullptr) trace->begin("valve-excite", {"t_s", "command_a", "current_a", "spool_m"});
  for (long k = 0; k < excite + probe; ++k) {
    const double i = command(k);
    rig.set_valve_command(i);
    rig.step();
    const sim::RigReadings reading = rig.read();
    r.command_a.push_back(i);
    r.current_a.push_back(reading.valve_current_a.value);
    r.spool_m.push_back(reading.spool_lvdt_m.value);
    if (trace != nullptr)
      trace->add({static_cast<double>(k + 1) * period, i, reading.valve_current_a.value, reading.spool_lvdt_m.value});
  }
  return r;
}

}  // namespace hsa::analyze
