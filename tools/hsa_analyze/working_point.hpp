// A working point of the rig as hsa-analyze's options write it: <position_m>:<load_kg>, e.g.
// 0.12:6 (rod position in metres, external load in kilograms, the paper's two coordinates of its
// identified plants, Puglisi et al. 2015, Table A3).
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <system_error>

namespace hsa::analyze {

struct WorkingPoint {
  double position_m = 0.0;
  double load_kg = 0.0;
};

// A finite number and nothing else.
inline std::optional<double> parse_number(std::string_view text) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc{} || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

// nullopt unless `text` is two finite numbers around one colon.
inline std::optional<WorkingPoint> parse_working_point(std::string_view text) {
  const auto colon = text.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  const auto position = parse_number(text.substr(0, colon));
  const auto load = parse_number(text.substr(colon + 1));
  if (!position || !load) return std::nullopt;
  return WorkingPoint{*position, *load};
}

}  // namespace hsa::analyze
