// Test fixture plugin "fixture_no_symbol": a valid shared library that does not export
// hsa_get_plugin_descriptor, as when a non-plugin .so ends up in the plugin directory.
extern "C" __attribute__((visibility("default"))) int fixture_no_symbol_answer() { return 42; }
