// The sim driver plugin as the daemon loads it: by name, from the build's plugin directory
// (HSA_PLUGIN_DIR, set by tests/drivers/CMakeLists.txt), configured from TOML text.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include <toml++/toml.h>

#include "drivers/plugin_loader.hpp"

namespace hsa::io {

inline constexpr Duration kSimTestPeriod = std::chrono::microseconds(100);

inline std::unique_ptr<DriverHandle> load_sim(const std::string& settings) {
  return PluginLoader({HSA_PLUGIN_DIR}).load_driver("rig", "sim", toml::parse(settings));
}

}  // namespace hsa::io
