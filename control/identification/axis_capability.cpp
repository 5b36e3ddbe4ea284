#include "control/identification/axis_capability.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hsa::control::identification {
namespace {

// The positive root of a·v² + b·v − c = 0 (a, c > 0, b ≥ 0).
double positive_root(double a, double b, double c) { return 2.0 * c / (b + std::sqrt(b * b + 4.0 * a * c)); }

DirectionCapability direction(double gain_m_s, double drive_n, double load_share_n, double friction_n, double sigma,
                              double flow_cap_m_s, const Identification& id, double margin) {
  // drive − load_share is the force at the hold point that k± was measured at; moving, friction
  // and damping take their part: (drive − load)·v² + k²·σ·v − k²·(drive − load − F_c) = 0.
  const double available = drive_n - load_share_n;
  if (!(available - friction_n > 0.0))
    throw std::invalid_argument("capability: the supply's force does not exceed the identified load and friction");
  DirectionCapability d;
  const double k2 = gain_m_s * gain_m_s;
  const double valve = positive_root(available, k2 * sigma, k2 * (available - friction_n));
  d.speed_pump_limited = flow_cap_m_s < valve;
  d.max_speed_m_s = std::min(valve, flow_cap_m_s);
  const double force = (available - friction_n) / id.motion.mass_kg.value;
  // The pump caps only the fed chamber's flow; the other drains through the valve at the valve's
  // rate, and the two chambers' springs drive the load pressure about equally (Ap²β/V_A against
  // α²·Ap²β/V_B, within 30 % of each other over the middle of the stroke): the speed that drives
  // the mode is the mean of the two.
  const double drive = d.speed_pump_limited ? 0.5 * (valve + flow_cap_m_s) : valve;
  const double mode = drive * peak_impulse_response(id.plant.b0.value, id.plant.b1.value);
  d.acceleration_force_limited = force < mode;
  d.max_acceleration_m_s2 = std::min(force, mode);
  d.speed_limit_m_s = margin * d.max_speed_m_s;
  d.acceleration_limit_m_s2 = margin * d.max_acceleration_m_s2;
  return d;
}

}  // namespace

double peak_impulse_response(double b0, double b1) {
  const double wn = std::sqrt(b0);
  const double zeta = b1 / (2.0 * wn);
  if (zeta < 1.0 - 1e-9) return wn * std::exp(-zeta * std::acos(zeta) / std::sqrt(1.0 - zeta * zeta));
  if (zeta <= 1.0 + 1e-9) return wn / std::exp(1.0);
  // Overdamped: h = wn²/(r1 − r2)·(e^{r1 t} − e^{r2 t}), peak where r1·e^{r1 t} = r2·e^{r2 t}.
  const double root = wn * std::sqrt(zeta * zeta - 1.0);
  const double r1 = -zeta * wn + root, r2 = -zeta * wn - root;
  const double t = std::log(r2 / r1) / (r1 - r2);
  return wn * wn / (r1 - r2) * (std::exp(r1 * t) - std::exp(r2 * t));
}

AxisCapability axis_capability(const Identification& id, double piston_area_m2, double area_ratio,
                               const SupplyRating& rating) {
  if (!(piston_area_m2 > 0.0) || !(area_ratio > 0.0 && area_ratio <= 1.0) || !(rating.supply_pressure_pa > 0.0) ||
      !(rating.pump_flow_m3_per_s > 0.0) || !(rating.margin > 0.0 && rating.margin <= 1.0))
    throw std::invalid_argument("capability: the area, area ratio, supply pressure and pump flow must be positive "
                                "and the margin in (0, 1]");
  const double fe = id.motion.external_force_n.value;
  const double fc = std::max(0.0, id.motion.dry_friction_n.value);
  const double sigma = std::max(0.0, id.motion.damping_n_s_per_m.value);
  const double ps = rating.supply_pressure_pa;
  AxisCapability c;
  c.margin = rating.margin;
  c.extend = direction(id.plant.k01.value * 1e-3, piston_area_m2 * ps, fe, fc, sigma,
                       rating.pump_flow_m3_per_s / piston_area_m2, id, rating.margin);
  // Retracting, the weight helps: its share enters with the opposite sign.
  c.retract = direction(std::abs(id.plant.k01_retracting.value) * 1e-3, area_ratio * piston_area_m2 * ps, -fe, fc,
                        sigma, rating.pump_flow_m3_per_s / (area_ratio * piston_area_m2), id, rating.margin);
  return c;
}

AxisCapability worst_capability(const std::vector<AxisCapability>& each, const std::vector<std::string>& names,
                                const std::vector<double>& loads_kg) {
  if (each.empty() || names.size() != each.size() || loads_kg.size() != each.size())
    throw std::invalid_argument("capability: no run, or names and loads that do not match the runs");
  AxisCapability worst = each.front();
  worst.extend.worst_run = worst.retract.worst_run = names.front();
  worst.extend.load_kg = worst.retract.load_kg = loads_kg.front();
  // The speed and the acceleration may come from different runs; both are kept as the minimum,
  // and the run named is the one with the lowest speed (the acceleration follows it on a rig
  // where the mode, not the force, limits it).
  const auto keep = [](DirectionCapability& w, const DirectionCapability& c, const std::string& name, double load) {
    if (c.max_speed_m_s < w.max_speed_m_s) {
      w.max_speed_m_s = c.max_speed_m_s;
      w.speed_limit_m_s = c.speed_limit_m_s;
      w.speed_pump_limited = c.speed_pump_limited;
      w.worst_run = name;
      w.load_kg = load;
    }
    if (c.max_acceleration_m_s2 < w.max_acceleration_m_s2) {
      w.max_acceleration_m_s2 = c.max_acceleration_m_s2;
      w.acceleration_limit_m_s2 = c.acceleration_limit_m_s2;
      w.acceleration_force_limited = c.acceleration_force_limited;
    }
  };
  for (std::size_t k = 1; k < each.size(); ++k) {
    keep(worst.extend, each[k].extend, names[k], loads_kg[k]);
    keep(worst.retract, each[k].retract, names[k], loads_kg[k]);
  }
  return worst;
}

}  // namespace hsa::control::identification
