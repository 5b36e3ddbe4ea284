// The binary interface between the daemon and a driver plugin (a shared library loaded with
// dlopen).
//
// A plugin exports one C symbol, hsa_get_plugin_descriptor, returning a static descriptor. The
// descriptor's first field is the ABI version and never moves, so a loader of any version can
// read it and refuse a plugin built against another one instead of calling through a vtable
// whose layout changed. Behind that check the plugin's C++ Driver object crosses the boundary:
// plugins are built with the same compiler and headers as the daemon, and the version is bumped
// whenever driver.hpp, channel.hpp or this descriptor change in a way that breaks binaries.
#pragma once

#include <cstdint>

#include "drivers/driver.hpp"

// Bump on any binary-incompatible change to the Driver interface, ChannelSlot or the descriptor.
// Version 2 added Driver::make_safe and Driver::failure_reason; version 3 Driver::check_settings;
// version 4 Driver::health; version 5 Driver::plan (the devices it opens and the channels it
// declares).
#define HSA_PLUGIN_ABI_VERSION 5u

extern "C" {

struct hsa_plugin_descriptor {
  std::uint32_t abi_version;  // HSA_PLUGIN_ABI_VERSION the plugin was built with; stays first
  const char* name;           // the plugin's name, e.g. "sim"
  // A new, unconfigured driver, or nullptr when it cannot be created. Never throws.
  hsa::io::Driver* (*create)();
  // Destroys a driver from create(). The library allocated it, so the library frees it.
  void (*destroy)(hsa::io::Driver* driver);
};

// Declared here with default visibility so that plugins can build with hidden visibility and
// still export their entry point.
__attribute__((visibility("default"))) const hsa_plugin_descriptor* hsa_get_plugin_descriptor();

}  // extern "C"

namespace hsa::io {

inline constexpr const char* plugin_entry_symbol = "hsa_get_plugin_descriptor";

}  // namespace hsa::io

// Defines a plugin's entry point for a default-constructible Driver class:
//   HSA_DRIVER_PLUGIN("sim", hsa::io::sim::SimDriver)
#define HSA_DRIVER_PLUGIN(plugin_name, DriverClass)                               \
  extern "C" const hsa_plugin_descriptor* hsa_get_plugin_descriptor() {          \
    static const hsa_plugin_descriptor descriptor{                               \
        HSA_PLUGIN_ABI_VERSION,                                                  \
        plugin_name,                                                             \
        []() -> ::hsa::io::Driver* {                                             \
          try {                                                                  \
            return new DriverClass();                                            \
          } catch (...) {                                                        \
            return nullptr;                                                      \
          }                                                                      \
        },                                                                       \
        [](::hsa::io::Driver* driver) { delete driver; },                        \
    };                                                                           \
    return &descriptor;                                                          \
  }
