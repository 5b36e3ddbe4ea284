#include "control/identification/identify_set.hpp"

#include <cmath>
#include <stdexcept>

namespace hsa::control::identification {

PlantSetEntry set_entry(const std::string& name, double load_kg, const Identification& id) {
  const auto per_metre = [](const Estimate& mm) { return Estimate{mm.value * 1e-3, mm.std_dev * 1e-3}; };
  PlantSetEntry p;
  p.name = name;
  p.position_m = id.working_point_m;
  p.load_kg = load_kg;
  p.b0_per_s2 = id.plant.b0;
  p.b1_per_s = id.plant.b1;
  p.k01_m_s = per_metre(id.plant.k01);
  p.k01_retracting_m_s = per_metre(id.plant.k01_retracting);
  p.k01_retracting_m_s.value = std::abs(p.k01_retracting_m_s.value);
  p.delay_s = id.plant.delay_s;
  p.kp_per_m = id.kp_per_m;
  p.fit_index = id.fit_index;
  return p;
}

SetIdentification identify_set(const std::vector<NamedRun>& runs, const IdentifyOptions& options,
                               const SupplyRating& rating) {
  if (runs.empty()) throw std::invalid_argument("plant set: no run");
  SetIdentification s;
  std::vector<PlantEstimate> candidates;
  std::vector<RunRecord> records;
  std::vector<std::string> names;
  std::vector<double> loads;
  const double area = options.hydraulics.piston_area_m2, ratio = options.hydraulics.area_ratio;
  for (const NamedRun& r : runs) {
    for (const std::string& n : names)
      if (n == r.name) throw std::invalid_argument("plant set: two runs are named " + r.name);
    try {
      s.each.push_back(identify_run(r.run, options));
    } catch (const RunRefused& e) {
      throw RunRefused(r.name + ": " + e.what());
    }
    const Identification& id = s.each.back();
    s.capability.push_back(axis_capability(id, area, ratio, rating));
    candidates.push_back(id.plant);
    records.push_back({&r.run.setpoint_m, &r.run.position_m, r.run.period_s, id.kp_per_m,
                       id.plant.leak_speed_mm_per_s});
    names.push_back(r.name);
    loads.push_back(r.load_kg);
    s.set.plants.push_back(set_entry(r.name, r.load_kg, id));
  }
  s.nominal = choose_nominal(candidates, records);
  s.set.nominal = s.nominal.index;
  for (std::size_t i = 0; i < s.set.plants.size(); ++i) s.set.plants[i].nominal_score = s.nominal.scores[i];
  s.set.capability = worst_capability(s.capability, names, loads);
  s.set.supply_pressure_pa = rating.supply_pressure_pa;
  s.set.pump_flow_m3_per_s = rating.pump_flow_m3_per_s;
  s.set.piston_area_m2 = area;
  s.set.area_ratio = ratio;
  return s;
}

}  // namespace hsa::control::identification
