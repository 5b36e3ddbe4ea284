// What the plant can follow, per direction of travel: the speed and acceleration a motion profile
// may ask for, from the axis's plant-set file (`hsa-analyze identify --set`, [capability]
// speed_limit_m_s and acceleration_limit_m_s2: a margin below what the valve can give at the worst
// load among the identified runs; control/identification/axis_capability.hpp derives them,
// docs/plant-set.md lists them). Extending is travel towards larger rod positions (a positive
// valve opening), retracting towards smaller ones.
//
// Infinite: no plant set, nothing identified; the axis's configured bounds are then its only ones.
#pragma once

#include <limits>
#include <string_view>

namespace hsa::daemon {

struct DirectionLimit {
  double speed_m_s = std::numeric_limits<double>::infinity();
  double accel_m_s2 = std::numeric_limits<double>::infinity();
};

enum class Travel : unsigned char { extend, retract };

struct MotionCapability {
  DirectionLimit extend, retract;

  [[nodiscard]] const DirectionLimit& of(Travel t) const noexcept { return t == Travel::extend ? extend : retract; }
  // Both directions' smaller figure, and the direction it belongs to (extending on a tie).
  [[nodiscard]] Travel slower() const noexcept {
    return retract.speed_m_s < extend.speed_m_s ? Travel::retract : Travel::extend;
  }
  [[nodiscard]] Travel weaker() const noexcept {
    return retract.accel_m_s2 < extend.accel_m_s2 ? Travel::retract : Travel::extend;
  }
};

// "extending", "retracting": how messages name a direction.
[[nodiscard]] constexpr std::string_view travelling(Travel t) noexcept {
  return t == Travel::extend ? "extending" : "retracting";
}

}  // namespace hsa::daemon
