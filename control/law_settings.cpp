#include "control/law_settings.hpp"

#include <cstdio>

namespace hsa::control {

std::string format_setting(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

}  // namespace hsa::control
