#include "control/pi_tuning.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace hsa::control {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The worse of the settling and recovery times over the set, or +∞ when the gains fail the
// margins on some plant (or do not settle or recover): the search's objective.
double cost(const SetPerformance& p) {
  const double t = std::max(p.worst_settling_s, p.worst_recovery_s);
  return p.feasible() && std::isfinite(p.worst_settling_s) && std::isfinite(p.worst_recovery_s) ? t : kInf;
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

SetPerformance evaluate_on_set(const GainGate& gate, const PiGainsSi& gains, int step_samples) {
  SetPerformance p{.verdict = gate.judge(gains)};
  const std::vector<IdentifiedPlant>& plants = gate.plants.plants;
  p.min_crossover_rad_s = kInf;
  for (const IdentifiedPlant& plant : plants) {
    p.min_crossover_rad_s = std::min(p.min_crossover_rad_s, stability_margins(plant.plant(), gains).crossover_rad_s);
  }
  if (p.verdict.unstable_plants > 0 || step_samples == 0) {
    p.worst_settling_s = std::numeric_limits<double>::quiet_NaN();
    p.worst_recovery_s = std::numeric_limits<double>::quiet_NaN();
    return p;
  }
  for (std::size_t i = 0; i < plants.size(); ++i) {
    const StepMetrics s = step_metrics(plants[i].plant(), gains, step_samples);
    keep_worse(s.settling_s, i, p.worst_settling_s, p.worst_settling_plant);
    const DisturbanceMetrics d = disturbance_response(plants[i].plant(), gains, step_samples);
    keep_worse(d.recovery_s, i, p.worst_recovery_s, p.worst_recovery_plant);
    if (s.overshoot_pct > p.worst_overshoot_pct) {
      p.worst_overshoot_pct = s.overshoot_pct;
      p.worst_overshoot_plant = i;
    }
  }
  return p;
}

std::optional<Tuning> tune_pi(const GainGate& gate, const SearchBox& limits, std::optional<PiGainsSi> start) {
  if (gate.plants.plants.empty()) throw std::invalid_argument("tune_pi: no plants");
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
    if (!gate.judge(g).passed()) return kInf;
    return cost(evaluate_on_set(gate, g, kSearchStepSamples));
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
  t.performance = evaluate_on_set(gate, t.gains);
  t.candidates = candidates;
  // The search compared steps of kSearchStepSamples; between two nearly equal candidates the
  // full resolution may reverse the order. The running gains are kept unless truly beaten.
  if (start && start->kp > 0.0 && start->ki > 0.0) {
    const SetPerformance running = evaluate_on_set(gate, *start);
    if (cost(running) <= cost(t.performance)) {
      t.gains = *start;
      t.performance = running;
    }
  }
  return t;
}

}  // namespace hsa::control
