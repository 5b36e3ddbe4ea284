#include "control/gain_gate.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "control/loop_analysis.hpp"
#include "control/setting_range.hpp"

namespace hsa::control {

namespace {

std::string format(const char* fmt, double value) {
  char text[48];
  std::snprintf(text, sizeof text, fmt, value);
  return text;
}

// Working point first, then the coefficients: an order of the plants that does not depend on
// where they sit in the set, for ties.
auto key_of(const IdentifiedPlant& p) { return std::tie(p.position_mm, p.load_kg, p.b0, p.b1, p.k01); }

// `candidate` is worse than `current` by `value` (smaller is worse; NaN is the worst), ties
// broken by working point.
bool worse(double candidate, const IdentifiedPlant& candidate_plant, double current,
           const IdentifiedPlant& current_plant) {
  const double a = std::isnan(candidate) ? -std::numeric_limits<double>::infinity() : candidate;
  const double b = std::isnan(current) ? -std::numeric_limits<double>::infinity() : current;
  if (a != b) return a < b;
  return key_of(candidate_plant) < key_of(current_plant);
}

}  // namespace

GatePlantSet table_a3_plant_set() {
  GatePlantSet set{.name = "Table A3", .plants = {kTableA3.begin(), kTableA3.end()}, .nominal = 0,
               .uncertainty = kTableA3Uncertainty};
  for (std::size_t i = 0; i < set.plants.size(); ++i) {
    if (set.plants[i].position_mm == 120 && set.plants[i].load_kg == 6) set.nominal = i;  // eq 51
  }
  return set;
}

GatePlantSet gate_plant_set(const PlantSet& set, std::string name) {
  GatePlantSet gate{.name = std::move(name), .plants = {}, .nominal = set.nominal, .uncertainty = std::nullopt};
  for (const PlantSetEntry& e : set.plants) {
    gate.plants.push_back({.position_mm = static_cast<int>(std::lround(e.position_m * 1e3)),
                           .load_kg = static_cast<int>(std::lround(e.load_kg)),
                           .b0 = e.b0_per_s2.value,
                           .b1 = e.b1_per_s.value,
                           .k01 = e.k01_m_s.value * 1e3});
  }
  return gate;
}

std::string plant_name(const IdentifiedPlant& plant) {
  return std::to_string(plant.load_kg) + " kg / " + std::to_string(plant.position_mm) + " mm";
}

GateVerdict judge_gains(const GatePlantSet& set, const MarginRequirements& min, const PiGainsSi& gains) {
  if (set.plants.empty()) throw std::invalid_argument("gain gate: the plant set '" + set.name + "' is empty");
  GateVerdict v;
  std::optional<PlantVerdict> worst_unstable;
  bool first = true;
  for (const IdentifiedPlant& plant : set.plants) {
    const CylinderPlant p = plant.plant();
    PlantVerdict pv{.plant = plant,
                    .stable = closed_loop_poles(p, gains).front().real() < 0.0,
                    .margins = stability_margins(p, gains)};
    if (first || worse(pv.margins.gain_margin_db, plant, v.worst_gain_margin.margins.gain_margin_db,
                       v.worst_gain_margin.plant)) {
      v.worst_gain_margin = pv;
    }
    if (first || worse(pv.margins.phase_margin_deg, plant, v.worst_phase_margin.margins.phase_margin_deg,
                       v.worst_phase_margin.plant)) {
      v.worst_phase_margin = pv;
    }
    first = false;
    if (!pv.stable) {
      ++v.unstable_plants;
      if (!worst_unstable || worse(pv.margins.gain_margin_db, plant, worst_unstable->margins.gain_margin_db,
                                   worst_unstable->plant)) {
        worst_unstable = pv;
      }
    }
  }
  if (set.uncertainty) v.small_gain = weighted_complementary_sensitivity(*set.uncertainty, gains);

  const std::string of_set = " of the " + std::to_string(set.plants.size()) + " plants of " + set.name;
  if (worst_unstable) {
    // Without a phase crossover the phase stays below −180° at every frequency (too much Ki for
    // the Kp): there is no gain margin to give.
    const double gm = worst_unstable->margins.gain_margin_db;
    v.refusal = "unstable on plant " + plant_name(worst_unstable->plant) + " (" +
                (std::isfinite(gm) ? "GM " + format("%.2f", gm) + " dB" : std::string("phase below -180° at every frequency")) +
                "), " + std::to_string(v.unstable_plants) + of_set;
  } else if (worse(v.worst_gain_margin.margins.gain_margin_db, v.worst_gain_margin.plant, min.min_gain_margin_db,
                   v.worst_gain_margin.plant)) {
    v.refusal = "gain margin " + format("%.2f", v.worst_gain_margin.margins.gain_margin_db) + " dB on plant " +
                plant_name(v.worst_gain_margin.plant) + " below the minimum " +
                format_setting(min.min_gain_margin_db) + " dB (min_gain_margin_db)";
  } else if (worse(v.worst_phase_margin.margins.phase_margin_deg, v.worst_phase_margin.plant,
                   min.min_phase_margin_deg, v.worst_phase_margin.plant)) {
    v.refusal = "phase margin " + format("%.2f", v.worst_phase_margin.margins.phase_margin_deg) + "° on plant " +
                plant_name(v.worst_phase_margin.plant) + " below the minimum " +
                format_setting(min.min_phase_margin_deg) + "° (min_phase_margin_deg)";
  } else if (v.small_gain && !v.small_gain->nominal_stable) {
    v.refusal = "unstable on the nominal plant P0 of " + set.name + " (Puglisi et al. 2015, eq 52)";
  } else if (v.small_gain && !(v.small_gain->norm <= 1.0)) {
    v.refusal = "robust stability not shown: ||W1 T0||inf = " + format("%.3f", v.small_gain->norm) + " > 1 at " +
                format("%.1f", v.small_gain->peak_rad_s) + " rad/s (small-gain condition, Puglisi et al. 2015, eq 61)";
  }
  return v;
}

std::string GainGate::describe(const PiGainsSi& gains) const {
  const GateVerdict v = judge(gains);
  std::string text = "    gain gate     " + std::to_string(plants.plants.size()) + " plants of " + plants.name +
                     ", gain margin >= " + format_setting(min.min_gain_margin_db) + " dB, phase margin >= " +
                     format_setting(min.min_phase_margin_deg) + " deg, " +
                     (plants.uncertainty ? "||W1 T0||inf <= 1 (eq 61)" : "no small-gain test (the set has no W1)") +
                     "\n                  these gains: worst gain margin " +
                     format("%.2f", v.worst_gain_margin.margins.gain_margin_db) + " dB (" +
                     plant_name(v.worst_gain_margin.plant) + "), worst phase margin " +
                     format("%.2f", v.worst_phase_margin.margins.phase_margin_deg) + " deg (" +
                     plant_name(v.worst_phase_margin.plant) + ")";
  if (v.small_gain) text += ", ||W1 T0||inf " + format("%.3f", v.small_gain->norm);
  return text + "\n";
}

}  // namespace hsa::control
