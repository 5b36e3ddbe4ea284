// Test fixture plugin "fixture_wrong_abi": exports a descriptor claiming an ABI version this
// build does not speak, as a plugin built against an older or newer hsa would. The loader must
// refuse it after reading abi_version and before touching anything else.
#include "drivers/plugin_abi.hpp"

extern "C" const hsa_plugin_descriptor* hsa_get_plugin_descriptor() {
  static const hsa_plugin_descriptor descriptor{
      HSA_PLUGIN_ABI_VERSION + 1,
      "fixture_wrong_abi",
      nullptr,
      nullptr,
  };
  return &descriptor;
}
