// The one range type of every configuration reader, and the one way a number is written in their
// messages. Header-only and free of any file format, so that control/ (the laws' settings) and
// drivers/ (the TOML reader the daemon and the plugins share) use the same words for the same
// bound: "a finite number in (0, 5]".
#pragma once

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace hsa::control {

// A number as configuration messages write it: up to 10 significant digits, 0.001, 1e-06, 85.
inline std::string format_setting(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

// An interval of finite numbers, an end possibly excluded, and how a message words it.
struct SettingRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  bool max_exclusive = false;

  [[nodiscard]] bool contains(double value) const {
    if (!std::isfinite(value)) return false;
    const bool above_min = min_exclusive ? value > min : value >= min;
    const bool below_max = max_exclusive ? value < max : value <= max;
    return above_min && below_max;
  }

  [[nodiscard]] std::string expected() const {
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

  static SettingRange any() { return {}; }
  static SettingRange positive(double max = std::numeric_limits<double>::infinity()) {
    return {.min = 0.0, .max = max, .min_exclusive = true};
  }
  static SettingRange non_negative() { return {.min = 0.0}; }
  static SettingRange above(double min) { return {.min = min, .min_exclusive = true}; }
  static SettingRange closed(double min, double max) { return {.min = min, .max = max}; }
};

}  // namespace hsa::control
