// Finds driver plugins and loads them with dlopen.
//
// A plugin is asked for by name ("sim" → libhsa_driver_sim.so, searched in a list of
// directories, first match wins) or by path (anything containing a '/'). Every failure throws a
// PluginError whose kind says what went wrong and whose message names the plugin and the file.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin.hpp"
#include "drivers/plugin_error.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io {

class PluginLoader {
 public:
  explicit PluginLoader(std::vector<std::filesystem::path> search_dirs);

  // "sim" → "libhsa_driver_sim.so".
  static std::string file_name(std::string_view plugin_name);

  [[nodiscard]] const std::vector<std::filesystem::path>& search_dirs() const { return dirs_; }

  // Opens the library and checks its descriptor. Throws PluginError.
  [[nodiscard]] std::shared_ptr<const Plugin> load(std::string_view name_or_path) const;

  // load(), create a driver named `instance` and configure it with `settings`: the daemon's
  // start-up path. Throws PluginError (configure_failed carries the driver's own message).
  [[nodiscard]] std::unique_ptr<DriverHandle> load_driver(std::string instance,
                                                          std::string_view name_or_path,
                                                          const toml::table& settings) const;

 private:
  std::vector<std::filesystem::path> dirs_;
};

// Where the daemon looks for plugins: the directories in $HSA_PLUGIN_PATH (colon-separated),
// then, for a program run from the build tree only, the build tree's plugin directory, then the
// install prefix's (<libdir>/hsa/plugins).
std::vector<std::filesystem::path> default_plugin_dirs();
// Whether this program's executable lies inside the build tree it was built in.
bool running_from_build_tree();
// Whether `file` lies inside `dir`, compared by whole path components (/a/build2 is not in /a/build).
bool path_is_within(const std::filesystem::path& dir, const std::filesystem::path& file);

}  // namespace hsa::io
