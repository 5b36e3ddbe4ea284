// An identification record of the proportional valve (Canuto et al. 2014, section 2) made on the
// simulated rig: the valve open loop, its solenoid current reference stepped at the valve rate
// (10 kHz) by a pseudo-random multi-level sequence (control/excitation_sequence.hpp) around a bias,
// then a probe above the current limit. control/identification/valve_fit.hpp fits it.
//
// The sequence, and why:
// - the rig starts at rest at hydraulic zero, holding the bias current I_0 (eq 5);
// - PRMS: `levels` currents evenly spaced over bias ± amplitude, a new one every 1…max_hold
//   switching times. Level spacings below the dead band's width and steps across it show the
//   band; 15 ms switching lets the 50 Hz mode ring (about 0.7 periods) and the holds of up to 60 ms
//   let it settle, which shows the static gain. The defaults keep the paper's valve inside its
//   stroke: the play sits about w/2 below the current, so bias 1.18 A centres the spool near
//   −0.6 mm and ±0.55 A moves it about ±0.75 mm, with room for the 37 % overshoot of its ζ = 0.3
//   (the record spans −1.8 … +0.6 mm before the probe, mean −0.64 mm);
// - the probe (probe_a > 0): a 0.1 s ramp from the bias to probe_a, 0.05 s there, a 0.1 s ramp
//   back and 0.1 s at the bias. Above the limit I_max the measured current stays at I_max (eq 1),
//   and the spool rests on its end stop X_max (eq 3): the record shows both.
// For another valve pick the bias that holds its spool a little below mid-stroke (a slow current
// ramp shows it) and an amplitude of about a third of the current that moves it over the stroke.
//
// CSV columns (with --csv; Trace adds the first): case ("valve-excite"), t_s (the end of the
// sample period), command_a (the reference held over that period), current_a (the measured
// solenoid current at t_s), spool_m (the LVDT reading at t_s, from hydraulic zero).
#pragma once

#include <cstdint>

#include "control/identification/valve_fit.hpp"
#include "sim/proportional_valve.hpp"
#include "tools/hsa_analyze/experiments.hpp"

namespace hsa::analyze {

struct ValveExcitation {
  double bias_a = 1.18;
  double amplitude_a = 0.55;
  double switching_time_s = 0.015;
  int levels = 7;
  int max_hold_switches = 4;
  double duration_s = 6.0;  // the PRMS part
  double probe_a = 3.5;     // 0: no probe
  std::uint64_t seed = 7;   // the PRMS's; the rig's noise has its own (sim::RigConfig::seed)
};

// The record at the rig's step (the valve rate), from a rig with this valve and rig seed.
control::identification::ValveRecord run_valve_excitation(const ValveExcitation& excitation,
                                                          const sim::ProportionalValveParameters& valve = {},
                                                          std::uint64_t rig_seed = 1, Trace* trace = nullptr);

}  // namespace hsa::analyze
