#include "control/law_settings.hpp"

#include <cmath>
#include <cstdio>

namespace hsa::control {

bool SettingRange::contains(double value) const {
  if (!std::isfinite(value)) return false;
  const bool above_min = min_exclusive ? value > min : value >= min;
  const bool below_max = max_exclusive ? value < max : value <= max;
  return above_min && below_max;
}

std::string SettingRange::expected() const {
  const bool has_min = std::isfinite(min);
  const bool has_max = std::isfinite(max);
  if (has_min && has_max) {
    return "a finite number in " + std::string(min_exclusive ? "(" : "[") + format_setting(min) + ", " +
           format_setting(max) + (max_exclusive ? ")" : "]");
  }
  if (has_min) return "a finite number " + std::string(min_exclusive ? "> " : ">= ") + format_setting(min);
  if (has_max) return "a finite number " + std::string(max_exclusive ? "< " : "<= ") + format_setting(max);
  return "a finite number";
}

std::string format_setting(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

}  // namespace hsa::control
