// Test fixture plugin "fixture_abi_v1": exports a descriptor of plugin ABI 1, the version before
// Driver::make_safe, as a plugin built against an older hsa would. The loader must refuse it with
// a message that says what changed and that the plugin needs a rebuild.
#include "drivers/plugin_abi.hpp"

extern "C" const hsa_plugin_descriptor* hsa_get_plugin_descriptor() {
  static const hsa_plugin_descriptor descriptor{
      1u,
      "fixture_abi_v1",
      nullptr,
      nullptr,
  };
  return &descriptor;
}
