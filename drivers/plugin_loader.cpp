#include "drivers/plugin_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <system_error>
#include <utility>

namespace hsa::io {

std::string_view to_string(PluginErrorKind kind) {
  switch (kind) {
    case PluginErrorKind::not_found: return "not found";
    case PluginErrorKind::open_failed: return "cannot be opened";
    case PluginErrorKind::symbol_missing: return "symbol missing";
    case PluginErrorKind::abi_mismatch: return "ABI version mismatch";
    case PluginErrorKind::create_failed: return "driver creation failed";
    case PluginErrorKind::configure_failed: return "configure failed";
  }
  return "unknown plugin error";
}

Plugin::Plugin(void* handle, const hsa_plugin_descriptor& descriptor, std::filesystem::path path)
    : handle_(handle), descriptor_(descriptor), path_(std::move(path)) {}

Plugin::~Plugin() { dlclose(handle_); }

namespace {

// Closes a dlopen handle unless released: the loader's failure paths must not leak the library.
struct HandleGuard {
  void* handle;
  ~HandleGuard() {
    if (handle != nullptr) dlclose(handle);
  }
  void* release() { return std::exchange(handle, nullptr); }
};

bool is_path(std::string_view name_or_path) {
  return name_or_path.find('/') != std::string_view::npos;
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

}  // namespace

PluginLoader::PluginLoader(std::vector<std::filesystem::path> search_dirs)
    : dirs_(std::move(search_dirs)) {}

std::string PluginLoader::file_name(std::string_view plugin_name) {
  return "libhsa_driver_" + std::string(plugin_name) + ".so";
}

std::shared_ptr<const Plugin> PluginLoader::load(std::string_view name_or_path) const {
  const std::string requested(name_or_path);
  std::filesystem::path path;
  std::error_code ec;
  if (is_path(name_or_path)) {
    path = requested;
    if (!std::filesystem::exists(path, ec)) {
      throw PluginError(PluginErrorKind::not_found, requested,
                        "plugin " + in_quotes(requested) + ": file not found");
    }
  } else {
    const std::string file = file_name(name_or_path);
    std::string searched;
    for (const auto& dir : dirs_) {
      if (std::filesystem::exists(dir / file, ec)) {
        path = dir / file;
        break;
      }
      searched += (searched.empty() ? "" : ", ") + dir.string();
    }
    if (path.empty()) {
      throw PluginError(PluginErrorKind::not_found, requested,
                        "plugin " + in_quotes(requested) + ": " + file + " not found in " +
                            (searched.empty() ? "an empty search path" : "[" + searched + "]"));
    }
  }
  const std::string where = "plugin " + in_quotes(requested) + " (" + path.string() + ")";

  // RTLD_NOW: an unresolved symbol fails here, with dlerror's text, not in the first RT cycle.
  // RTLD_LOCAL: two plugins may link the same static code without interposing on each other.
  dlerror();
  HandleGuard handle{dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)};
  if (handle.handle == nullptr) {
    const char* why = dlerror();
    throw PluginError(PluginErrorKind::open_failed, requested,
                      where + ": dlopen failed: " + (why != nullptr ? why : "unknown error"));
  }

  dlerror();
  void* symbol = dlsym(handle.handle, plugin_entry_symbol);
  if (symbol == nullptr) {
    throw PluginError(PluginErrorKind::symbol_missing, requested,
                      where + ": does not export " + plugin_entry_symbol +
                          "(); is it an hsa driver plugin?");
  }
  using Entry = const hsa_plugin_descriptor* (*)();
  const hsa_plugin_descriptor* descriptor = reinterpret_cast<Entry>(symbol)();
  if (descriptor == nullptr) {
    throw PluginError(PluginErrorKind::symbol_missing, requested,
                      where + ": " + plugin_entry_symbol + "() returned no descriptor");
  }
  // Only abi_version may be read before it has been checked: the rest of the layout is what
  // the version guards.
  if (descriptor->abi_version >= 1 && descriptor->abi_version < HSA_PLUGIN_ABI_VERSION) {
    // An older version: say what it lacks, so the fix is obvious.
    static constexpr const char* kAddedIn[] = {"", "", "make_safe", "check_settings", "health", "plan"};
    static_assert(std::size(kAddedIn) == HSA_PLUGIN_ABI_VERSION + 1, "name what the new version added");
    throw PluginError(PluginErrorKind::abi_mismatch, requested,
                      where + ": was built for plugin ABI " + std::to_string(descriptor->abi_version) + " (before " +
                          kAddedIn[descriptor->abi_version + 1] + "); this hsad needs ABI " +
                          std::to_string(HSA_PLUGIN_ABI_VERSION) + ": rebuild it");
  }
  if (descriptor->abi_version != HSA_PLUGIN_ABI_VERSION) {
    throw PluginError(PluginErrorKind::abi_mismatch, requested,
                      where + ": built for plugin ABI version " +
                          std::to_string(descriptor->abi_version) + ", this program needs " +
                          std::to_string(HSA_PLUGIN_ABI_VERSION) + "; rebuild the plugin");
  }
  if (descriptor->name == nullptr || descriptor->create == nullptr ||
      descriptor->destroy == nullptr) {
    throw PluginError(PluginErrorKind::symbol_missing, requested,
                      where + ": descriptor lacks a name, create or destroy");
  }
  return std::make_shared<const Plugin>(handle.release(), *descriptor, path);
}

std::unique_ptr<DriverHandle> PluginLoader::load_driver(std::string instance,
                                                        std::string_view name_or_path,
                                                        const toml::table& settings) const {
  auto handle = std::make_unique<DriverHandle>(std::move(instance), load(name_or_path));
  if (Result configured = handle->configure(settings); !configured) {
    throw PluginError(PluginErrorKind::configure_failed, std::string(name_or_path),
                      configured.message());
  }
  return handle;
}

bool path_is_within(const std::filesystem::path& dir, const std::filesystem::path& file) {
  const std::filesystem::path d = dir.lexically_normal(), f = file.lexically_normal();
  auto [d_end, f_at] = std::mismatch(d.begin(), d.end(), f.begin(), f.end());
  if (d_end != d.end() && d_end->empty() && std::next(d_end) == d.end()) ++d_end;  // a trailing '/'
  return d_end == d.end() && f_at != f.end();
}

bool running_from_build_tree() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return !error && path_is_within(HSA_BUILD_TREE_DIR, exe);
}

std::vector<std::filesystem::path> default_plugin_dirs() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("HSA_PLUGIN_PATH"); env != nullptr) {
    std::string_view rest(env);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      if (const auto dir = rest.substr(0, colon); !dir.empty()) dirs.emplace_back(dir);
      rest = colon == std::string_view::npos ? std::string_view{} : rest.substr(colon + 1);
    }
  }
  // The build tree's plugins only for a program that runs from the build tree: an installed hsad
  // must not load whatever a build directory on the same machine holds.
  if (running_from_build_tree()) dirs.emplace_back(HSA_BUILD_PLUGIN_DIR);
  dirs.emplace_back(HSA_INSTALL_PLUGIN_DIR);
  return dirs;
}

}  // namespace hsa::io
