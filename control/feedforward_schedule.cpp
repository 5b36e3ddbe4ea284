#include "control/feedforward_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace hsa::control {

FeedforwardSchedule make_feedforward_schedule(std::span<const IdentifiedPlant> plants) {
  if (plants.empty()) throw std::invalid_argument("a feed-forward schedule needs at least one identified plant");
  std::vector<IdentifiedPlant> sorted(plants.begin(), plants.end());
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const IdentifiedPlant& a, const IdentifiedPlant& b) { return a.position_mm < b.position_mm; });
  FeedforwardSchedule s;
  std::size_t at_point = 0;  // plants averaged into the last point
  for (const IdentifiedPlant& p : sorted) {
    if (!(p.k01 > 0.0) || !(p.b0 > 0.0) || !(p.b1 > 0.0) || !std::isfinite(p.k01 * p.b0 * p.b1)) {
      throw std::invalid_argument("the plant at " + std::to_string(p.position_mm) +
                                  " mm cannot be inverted: k01, b0 and b1 must be positive");
    }
    const FeedforwardGains g = plant_inverse_gains(p.plant());
    const double position = p.position_m();
    if (s.count > 0 && std::abs(position - s.points[s.count - 1].position_m) < 0.5e-3) {
      FeedforwardGains& mean = s.points[s.count - 1].gains;
      const double n = static_cast<double>(++at_point);
      mean.velocity += (g.velocity - mean.velocity) / n;
      mean.accel += (g.accel - mean.accel) / n;
      mean.jerk += (g.jerk - mean.jerk) / n;
      continue;
    }
    if (s.count == FeedforwardSchedule::kMaxPoints) {
      throw std::invalid_argument("a feed-forward schedule takes at most " +
                                  std::to_string(FeedforwardSchedule::kMaxPoints) + " rod positions");
    }
    s.points[s.count++] = {position, g};
    at_point = 1;
  }
  return s;
}

}  // namespace hsa::control
