// Motion feed-forward that follows the working point: the inverted plant of the nearest identified
// working points, interpolated over the stroke.
//
// control/motion_feedforward.hpp inverts one plant, Puglisi et al. (2015) eqs 38 and 41:
//   u_ff = v / k01 + (b1 / (k01·b0))·a + (1 / (k01·b0))·j.
// The plant varies over the stroke: on the paper's Table A3, k01 runs from 224 to 294 mm/s and b0
// rises as the rod extends (the oil column on the rod side gets shorter). A feed-forward that
// inverts one working point is right there and drives the rod ahead of (or behind) its profile
// elsewhere, by the ratio of the two k01: what the PI then corrects at the end of the move is that
// ratio times the speed, and it shows as overshoot where the profile stops.
//
// The schedule keeps, per identified rod position, the three gains that invert that position's
// plant (Kv = 1/k01, Ka = b1/(k01·b0), Kj = 1/(k01·b0)), averaged over the loads identified there,
// and evaluates them at the setpoint's position by linear interpolation between the two neighbouring
// positions (held constant beyond the first and the last). Interpolating each gain is interpolating
// the inverse plant, which is what the gain-scheduling literature does for a plant identified at
// frozen operating points; the points are the identification's own, nothing is fitted.
//
// The gains invert the extending plant (k01 of eq 41 as `hsa-analyze identify` reports it) both
// ways. The retracting k01 the identification also reports is not used: with the extending
// plant's inverse, retracting moves on a rig identified this way overshoot no more than extending
// ones (docs/operation.md, Moves, gives the figures).
//
// Built off the RT thread (make_feedforward_schedule); evaluated on it with no allocation.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "control/motion_feedforward.hpp"
#include "control/plant_table.hpp"

namespace hsa::control {

struct FeedforwardSchedule {
  static constexpr std::size_t kMaxPoints = 32;
  struct Point {
    double position_m = 0.0;
    FeedforwardGains gains;
    bool operator==(const Point&) const = default;
  };
  std::array<Point, kMaxPoints> points{};  // sorted by position, strictly increasing
  std::size_t count = 0;                   // 0: no schedule

  [[nodiscard]] constexpr bool empty() const noexcept { return count == 0; }

  // The gains at rod position `position_m`: interpolated between the neighbouring points, the end
  // point's beyond the ends. A NaN position gives the first point's gains.
  [[nodiscard]] constexpr FeedforwardGains at(double position_m) const noexcept {
    if (count == 0) return {};
    if (!(position_m > points[0].position_m)) return points[0].gains;
    for (std::size_t i = 1; i < count; ++i) {
      if (position_m <= points[i].position_m) {
        const Point& a = points[i - 1];
        const Point& b = points[i];
        const double w = (position_m - a.position_m) / (b.position_m - a.position_m);
        return {a.gains.velocity + w * (b.gains.velocity - a.gains.velocity),
                a.gains.accel + w * (b.gains.accel - a.gains.accel),
                a.gains.jerk + w * (b.gains.jerk - a.gains.jerk)};
      }
    }
    return points[count - 1].gains;
  }

  bool operator==(const FeedforwardSchedule&) const = default;
};

// The schedule of a set of identified plants: one point per distinct position (plants within
// 0.5 mm of each other are one position), its gains the mean of plant_inverse_gains() over the
// plants there. Throws std::invalid_argument for an empty set, a plant that is not positive
// (k01, b0, b1 > 0) or more than kMaxPoints positions.
[[nodiscard]] FeedforwardSchedule make_feedforward_schedule(std::span<const IdentifiedPlant> plants);

}  // namespace hsa::control
