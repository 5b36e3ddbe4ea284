// The typed error of loading a driver plugin and bringing its driver up.
//
// The kind lets the daemon and the tests tell the causes apart without parsing text; the
// message is for the operator and always names the plugin and, once known, the file.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace hsa::io {

enum class PluginErrorKind : unsigned char {
  not_found,         // no such file, or no file for that name in any search directory
  open_failed,       // dlopen refused the file (not a shared library, unresolved symbol, ...)
  symbol_missing,    // the library does not export hsa_get_plugin_descriptor
  abi_mismatch,      // built against another HSA_PLUGIN_ABI_VERSION
  create_failed,     // the descriptor's create() returned no driver
  configure_failed,  // the driver's on_configure refused its settings
};

std::string_view to_string(PluginErrorKind kind);

class PluginError : public std::runtime_error {
 public:
  PluginError(PluginErrorKind kind, std::string plugin, const std::string& message)
      : std::runtime_error(message), kind_(kind), plugin_(std::move(plugin)) {}

  [[nodiscard]] PluginErrorKind kind() const { return kind_; }
  [[nodiscard]] const std::string& plugin() const { return plugin_; }  // as asked for: name or path

 private:
  PluginErrorKind kind_;
  std::string plugin_;
};

}  // namespace hsa::io
