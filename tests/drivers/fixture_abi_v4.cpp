// Test fixture plugin "fixture_abi_v4": exports a descriptor of plugin ABI 4, the version before
// Driver::plan, as a plugin built against an older hsa would. The loader must refuse it by its
// version, saying what changed and that the plugin needs a rebuild.
#include "drivers/plugin_abi.hpp"

extern "C" const hsa_plugin_descriptor* hsa_get_plugin_descriptor() {
  static const hsa_plugin_descriptor descriptor{
      4u,
      "fixture_abi_v4",
      nullptr,
      nullptr,
  };
  return &descriptor;
}
