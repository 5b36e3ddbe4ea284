#include "tools/hsactl/gains_file.hpp"

#include <cmath>
#include <optional>
#include <sstream>

#include <toml++/toml.h>

namespace hsa::ctl {
namespace {

std::string where(const std::string& path, const toml::source_region& r) {
  std::ostringstream s;
  s << path;
  if (r.begin.line > 0) s << ':' << r.begin.line << ':' << r.begin.column;
  return s.str();
}

double gain(const toml::table& t, const std::string& path, const char* key, bool zero_allowed) {
  const toml::node* node = t.get(key);
  if (node == nullptr) throw std::runtime_error(path + ": " + key + ": missing (expected a number, " +
                                                (zero_allowed ? ">= 0" : "> 0") + ")");
  const std::optional<double> v = node->value<double>();
  const bool ok = v && std::isfinite(*v) && (zero_allowed ? *v >= 0.0 : *v > 0.0);
  if (!ok) {
    std::ostringstream got;
    if (v) {
      got << *v;
    } else {
      got << "a " << node->type();
    }
    throw std::runtime_error(where(path, node->source()) + ": " + key + ": expected a number " +
                             (zero_allowed ? ">= 0" : "> 0") + ", got " + got.str());
  }
  return *v;
}

}  // namespace

GainsFromFile read_gains_file(const std::string& path) {
  toml::table t;
  try {
    t = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw std::runtime_error(where(path, e.source()) + ": " + std::string(e.description()));
  }
  return {.kp = gain(t, path, "kp", false), .ki = gain(t, path, "ki", true)};
}

}  // namespace hsa::ctl
