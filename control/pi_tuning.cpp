#include "control/pi_tuning.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hsa::control {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The worse of the settling and recovery times over the set, or +∞ when the gains fail the
// margins on some plant (or do not settle or recover): the search's objective.
double cost(const SetPerformance& p) {
  const double t = std::max(p.worst_settling_s, p.worst_recovery_s);
  return p.feasible && std::isfinite(p.worst_settling_s) && std::isfinite(p.worst_recovery_s) ? t : kInf;
}

// Keeps `value` of plant i when it is worse than `worst` (higher; NaN is worst of all, and stays).
void keep_worse(double value, std::size_t i, double& worst, std::size_t& plant) {
  if (std::isnan(worst)) return;
  if (std::isnan(value) || value > worst) {
    worst = value;
    plant = i;
  }
}

PiGainsSi gains_at(double log_kp, double log_corner) {
  const double kp = std::exp(log_kp);
  return {.kp = kp, .ki = kp * std::exp(log_corner)};
}

}  // namespace

SetPerformance evaluate_on_set(std::span<const CylinderPlant> plants, const PiGainsSi& gains,
                               const TuningLimits& limits, int step_samples) {
  if (plants.empty()) throw std::invalid_argument("evaluate_on_set: no plants");
  SetPerformance p{.stable = true,
                   .feasible = true,
                   .worst_gain_margin_db = kInf,
                   .worst_phase_margin_deg = kInf,
                   .worst_settling_s = 0.0,
                   .worst_recovery_s = 0.0,
                   .worst_overshoot_pct = 0.0,
                   .min_crossover_rad_s = kInf};
  for (std::size_t i = 0; i < plants.size(); ++i) {
    if (!(closed_loop_poles(plants[i], gains).front().real() < 0.0)) p.stable = false;
    const StabilityMargins m = stability_margins(plants[i], gains);
    if (m.gain_margin_db < p.worst_gain_margin_db) {
      p.worst_gain_margin_db = m.gain_margin_db;
      p.worst_gain_margin_plant = i;
    }
    // No gain crossover at all cannot happen with an integrator in the loop; NaN counts as worst.
    if (!std::isnan(p.worst_phase_margin_deg) && !(m.phase_margin_deg >= p.worst_phase_margin_deg)) {
      p.worst_phase_margin_deg = m.phase_margin_deg;
      p.worst_phase_margin_plant = i;
    }
    if (m.crossover_rad_s < p.min_crossover_rad_s) p.min_crossover_rad_s = m.crossover_rad_s;
  }
  p.feasible = p.stable && p.worst_gain_margin_db >= limits.min_gain_margin_db &&
               p.worst_phase_margin_deg >= limits.min_phase_margin_deg;
  if (!p.stable || step_samples == 0) {
    p.worst_settling_s = std::numeric_limits<double>::quiet_NaN();
    p.worst_recovery_s = std::numeric_limits<double>::quiet_NaN();
    return p;
  }
  for (std::size_t i = 0; i < plants.size(); ++i) {
    const StepMetrics s = step_metrics(plants[i], gains, step_samples);
    keep_worse(s.settling_s, i, p.worst_settling_s, p.worst_settling_plant);
    const DisturbanceMetrics d = disturbance_response(plants[i], gains, step_samples);
    keep_worse(d.recovery_s, i, p.worst_recovery_s, p.worst_recovery_plant);
    if (s.overshoot_pct > p.worst_overshoot_pct) {
      p.worst_overshoot_pct = s.overshoot_pct;
      p.worst_overshoot_plant = i;
    }
  }
  return p;
}

std::optional<Tuning> tune_pi(std::span<const CylinderPlant> plants, const TuningLimits& limits,
                              std::optional<PiGainsSi> start) {
  if (plants.empty()) throw std::invalid_argument("tune_pi: no plants");
  if (!(limits.kp_min > 0.0 && limits.kp_max > limits.kp_min && limits.corner_min > 0.0 &&
        limits.corner_max > limits.corner_min)) {
    throw std::invalid_argument("tune_pi: the search box must be positive and not empty");
  }
  const double lo_kp = std::log(limits.kp_min), hi_kp = std::log(limits.kp_max);
  const double lo_c = std::log(limits.corner_min), hi_c = std::log(limits.corner_max);

  int candidates = 0;
  const auto objective = [&](double log_kp, double log_corner) {
    ++candidates;
    // Margins first: they are cheap, and the steps are only needed where the margins hold.
    const PiGainsSi g = gains_at(log_kp, log_corner);
    if (!evaluate_on_set(plants, g, limits, 0).feasible) return kInf;
    return cost(evaluate_on_set(plants, g, limits, kSearchStepSamples));
  };

  // The grid: 32 × 16 cells over the box.
  constexpr int kKp = 32, kCorner = 16;
  double best = kInf, best_kp = 0.0, best_c = 0.0;
  for (int i = 0; i < kKp; ++i) {
    const double x = lo_kp + (hi_kp - lo_kp) * i / (kKp - 1);
    for (int j = 0; j < kCorner; ++j) {
      const double y = lo_c + (hi_c - lo_c) * j / (kCorner - 1);
      const double c = objective(x, y);
      if (c < best) {
        best = c;
        best_kp = x;
        best_c = y;
      }
    }
  }
  if (start && start->kp > 0.0 && start->ki > 0.0) {
    const double x = std::log(start->kp), y = std::log(start->ki / start->kp);
    const double c = objective(x, y);
    if (c <= best) {
      best = c;
      best_kp = x;
      best_c = y;
    }
  }
  if (!std::isfinite(best)) return std::nullopt;

  // Compass search from the best cell, inside the box.
  double step_kp = (hi_kp - lo_kp) / (kKp - 1), step_c = (hi_c - lo_c) / (kCorner - 1);
  while (step_kp > 1e-3 || step_c > 1e-3) {
    bool improved = false;
    const std::array<std::array<double, 2>, 4> moves{{{step_kp, 0.0}, {-step_kp, 0.0}, {0.0, step_c}, {0.0, -step_c}}};
    for (const auto& [dx, dy] : moves) {
      const double x = best_kp + dx, y = best_c + dy;
      if (x < lo_kp || x > hi_kp || y < lo_c || y > hi_c) continue;  // the box bounds the search
      const double c = objective(x, y);
      if (c < best) {
        best = c;
        best_kp = x;
        best_c = y;
        improved = true;
      }
    }
    if (!improved) {
      step_kp /= 2.0;
      step_c /= 2.0;
    }
  }

  Tuning t;
  t.gains = gains_at(best_kp, best_c);
  t.performance = evaluate_on_set(plants, t.gains, limits);
  t.candidates = candidates;
  // The search compared steps of kSearchStepSamples; between two nearly equal candidates the
  // full resolution may reverse the order. The running gains are kept unless truly beaten.
  if (start && start->kp > 0.0 && start->ki > 0.0) {
    const SetPerformance running = evaluate_on_set(plants, *start, limits);
    if (cost(running) <= cost(t.performance)) {
      t.gains = *start;
      t.performance = running;
    }
  }
  return t;
}

}  // namespace hsa::control
