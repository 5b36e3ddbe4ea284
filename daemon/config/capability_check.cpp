#include "daemon/config/capability_check.hpp"

#include <string>

#include "daemon/supervisor/safety_defaults.hpp"

namespace hsa::daemon {

namespace {

// "at most 0.119 m/s, what the plant can follow retracting (capability.retract.speed_limit_m_s of
// plants.toml)": what fail() prints after "expected".
std::string within(double limit, std::string_view unit, Travel travel, std::string_view key, const std::string& file) {
  return "at most " + io::format_setting(limit) + " " + std::string(unit) + ", what the plant can follow " +
         std::string(travelling(travel)) + " (capability." + (travel == Travel::extend ? "extend." : "retract.") +
         std::string(key) + " of " + file + ")";
}

}  // namespace

void apply_capability(const io::TableReader& axis, const LoadedPlantSet& plants, AxisConfig& a) {
  const auto& c = plants.set.capability;
  MotionCapability cap;
  cap.extend = {c.extend.speed_limit_m_s, c.extend.acceleration_limit_m_s2};
  cap.retract = {c.retract.speed_limit_m_s, c.retract.acceleration_limit_m_s2};

  // Every registered law reads its speed bound and its plant set from [axes.pi].
  const io::TableReader pi = *axis.table("pi", true, "a table of PI gains");
  const Travel slower = cap.slower();
  if (a.law->max_speed_m_s() > cap.of(slower).speed_m_s) {
    pi.fail("max_speed_m_s", within(cap.of(slower).speed_m_s, "m/s", slower, "speed_limit_m_s", plants.path));
  }
  const Travel weaker = cap.weaker();
  if (a.limits.max_accel_m_s2 > cap.of(weaker).accel_m_s2) {
    axis.table("limits", true, "")->fail(
        "max_accel_m_s2", within(cap.of(weaker).accel_m_s2, "m/s²", weaker, "acceleration_limit_m_s2", plants.path));
  }
  // Unset, the acceleration stays what it is without a plant set (the speed reached in
  // kDefaultRampS), lowered to the plant's limit only where that is smaller: the capability is
  // the most a profile may ask for, not a target.
  if (!(a.limits.max_accel_m_s2 > 0.0) &&
      a.law->max_speed_m_s() / safety_defaults::kDefaultRampS > cap.of(weaker).accel_m_s2) {
    a.limits.max_accel_m_s2 = cap.of(weaker).accel_m_s2;
  }
  a.capability = cap;
  a.capability_source = plants.path;
}

}  // namespace hsa::daemon
