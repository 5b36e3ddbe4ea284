#pragma once

// The valve nobody tuned for, as the valve-loop tests make it, and the record an operator takes to
// identify a valve (docs/valve-loop.md, "A valve other than the paper's").

#include "control/identification/valve_fit.hpp"
#include "control/valve_law.hpp"
#include "sim/proportional_valve.hpp"
#include "tools/hsa_analyze/valve_excitation.hpp"

namespace hsa::analyze::test {

// A wider dead band (0.5 A), a softer spring (40 Hz) and a lower current limit (2.5 A) than the
// paper's valve; everything else the paper's.
inline sim::ProportionalValveParameters variant_valve() {
  sim::ProportionalValveParameters v;
  v.hysteresis_width_a = 0.5;
  v.natural_frequency_hz = 40.0;
  v.current_max_a = 2.5;
  return v;
}

// The valve identified from a valve-excite record. The variant's bias and amplitude are picked for
// its stroke, as valve_excitation.hpp tells an operator to (`experiment valve --valve FILE
// --excite-bias 0.85`); the paper's valve takes the defaults.
inline control::identification::ValveFit fit_from_record(const sim::ProportionalValveParameters& valve, bool is_variant) {
  ValveExcitation excitation;
  if (is_variant) {
    excitation.bias_a = 0.85;
    excitation.amplitude_a = 0.55;
  }
  return control::identification::fit_valve(run_valve_excitation(excitation, valve));
}

inline control::IdentifiedValve identified_from_record(const sim::ProportionalValveParameters& valve, bool is_variant) {
  return control::identification::identified_valve(fit_from_record(valve, is_variant));
}

}  // namespace hsa::analyze::test
