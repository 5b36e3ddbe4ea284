// A loaded plugin library: the dlopen handle and the descriptor it exported.
//
// Drivers keep a shared_ptr to the Plugin that created them, so the library stays mapped until
// the last of its drivers is destroyed: dlclose never pulls code out from under a live vtable.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "drivers/plugin_abi.hpp"

namespace hsa::io {

class Plugin {
 public:
  // Takes ownership of `handle` (from dlopen); `descriptor` must come from that library.
  Plugin(void* handle, const hsa_plugin_descriptor& descriptor, std::filesystem::path path);
  ~Plugin();
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  [[nodiscard]] std::string name() const { return descriptor_.name; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] const hsa_plugin_descriptor& descriptor() const { return descriptor_; }

 private:
  void* handle_;
  const hsa_plugin_descriptor& descriptor_;
  std::filesystem::path path_;
};

}  // namespace hsa::io
