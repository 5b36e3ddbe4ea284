// The plugin loader against real shared libraries: one fixture plugin per failure mode.
#include "drivers/plugin_loader.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <toml++/toml.h>

namespace hsa::io {
namespace {

using ::testing::HasSubstr;

// Runs `load` and returns the PluginError it must throw.
template <typename F>
PluginError expect_plugin_error(F&& load) {
  try {
    load();
  } catch (const PluginError& e) {
    return e;
  }
  ADD_FAILURE() << "no PluginError thrown";
  return PluginError(PluginErrorKind::not_found, "", "");
}

PluginLoader fixture_loader() { return PluginLoader({HSA_FIXTURE_PLUGIN_DIR}); }

TEST(PluginLoader, LoadsAGoodPluginByPath) {
  const auto plugin = fixture_loader().load(HSA_FIXTURE_LOOPBACK_PATH);
  EXPECT_EQ(plugin->name(), "fixture_loopback");
  EXPECT_EQ(plugin->descriptor().abi_version, HSA_PLUGIN_ABI_VERSION);
  EXPECT_EQ(plugin->path(), std::filesystem::path(HSA_FIXTURE_LOOPBACK_PATH));
}

TEST(PluginLoader, FindsAPluginByNameInTheSearchDirectories) {
  const PluginLoader loader({"/nonexistent/first", HSA_FIXTURE_PLUGIN_DIR});
  const auto plugin = loader.load("fixture_loopback");
  EXPECT_EQ(plugin->name(), "fixture_loopback");
  EXPECT_EQ(plugin->path().filename(), "libhsa_driver_fixture_loopback.so");
}

TEST(PluginLoader, FileNameFollowsTheNamingScheme) {
  EXPECT_EQ(PluginLoader::file_name("sim"), "libhsa_driver_sim.so");
}

TEST(PluginLoader, ReportsAPathThatDoesNotExist) {
  const std::string path = std::string(HSA_FIXTURE_PLUGIN_DIR) + "/libhsa_driver_absent.so";
  const PluginError e = expect_plugin_error([&] { (void)fixture_loader().load(path); });
  EXPECT_EQ(e.kind(), PluginErrorKind::not_found);
  EXPECT_EQ(e.plugin(), path);
  EXPECT_THAT(e.what(), HasSubstr(path));
  EXPECT_THAT(e.what(), HasSubstr("file not found"));
}

TEST(PluginLoader, ReportsANameFoundInNoSearchDirectory) {
  const PluginLoader loader({"/nonexistent/a", "/nonexistent/b"});
  const PluginError e = expect_plugin_error([&] { (void)loader.load("modbus"); });
  EXPECT_EQ(e.kind(), PluginErrorKind::not_found);
  EXPECT_EQ(e.plugin(), "modbus");
  EXPECT_THAT(e.what(), HasSubstr("libhsa_driver_modbus.so not found in [/nonexistent/a, "
                                  "/nonexistent/b]"));
}

TEST(PluginLoader, ReportsAFileDlopenRefusesWithDlerrorText) {
  const PluginError e =
      expect_plugin_error([] { (void)fixture_loader().load(HSA_NOT_A_LIBRARY_PATH); });
  EXPECT_EQ(e.kind(), PluginErrorKind::open_failed);
  EXPECT_THAT(e.what(), HasSubstr("dlopen failed"));
  EXPECT_THAT(e.what(), HasSubstr(HSA_NOT_A_LIBRARY_PATH));
  // dlerror() names the file and the reason (glibc: "invalid ELF header" or "file too short").
  EXPECT_THAT(e.what(), HasSubstr("CMakeLists.txt:"));
}

TEST(PluginLoader, ReportsALibraryWithoutTheEntrySymbol) {
  const PluginError e =
      expect_plugin_error([] { (void)fixture_loader().load("fixture_no_symbol"); });
  EXPECT_EQ(e.kind(), PluginErrorKind::symbol_missing);
  EXPECT_EQ(e.plugin(), "fixture_no_symbol");
  EXPECT_THAT(e.what(), HasSubstr("hsa_get_plugin_descriptor"));
  EXPECT_THAT(e.what(), HasSubstr(HSA_FIXTURE_NO_SYMBOL_PATH));
}

TEST(PluginLoader, ReportsAnAbiVersionMismatch) {
  const PluginError e =
      expect_plugin_error([] { (void)fixture_loader().load(HSA_FIXTURE_WRONG_ABI_PATH); });
  EXPECT_EQ(e.kind(), PluginErrorKind::abi_mismatch);
  EXPECT_THAT(e.what(), HasSubstr("ABI version " + std::to_string(HSA_PLUGIN_ABI_VERSION + 1)));
  EXPECT_THAT(e.what(), HasSubstr("needs " + std::to_string(HSA_PLUGIN_ABI_VERSION)));
}

TEST(PluginLoader, RefusesAnAbi1PluginSayingItPredatesMakeSafe) {
  const PluginError e =
      expect_plugin_error([] { (void)fixture_loader().load(HSA_FIXTURE_ABI_V1_PATH); });
  EXPECT_EQ(e.kind(), PluginErrorKind::abi_mismatch);
  EXPECT_EQ(e.plugin(), HSA_FIXTURE_ABI_V1_PATH);
  EXPECT_THAT(e.what(), HasSubstr(HSA_FIXTURE_ABI_V1_PATH));
  EXPECT_THAT(e.what(), HasSubstr("was built for plugin ABI 1 (before make_safe); this hsad needs ABI " +
                                  std::to_string(HSA_PLUGIN_ABI_VERSION) + ": rebuild it"));
}

TEST(PluginLoader, RefusesAnAbi4PluginSayingItPredatesPlan) {
  const PluginError e =
      expect_plugin_error([] { (void)fixture_loader().load(HSA_FIXTURE_ABI_V4_PATH); });
  EXPECT_EQ(e.kind(), PluginErrorKind::abi_mismatch);
  EXPECT_THAT(e.what(), HasSubstr(HSA_FIXTURE_ABI_V4_PATH));
  EXPECT_THAT(e.what(), HasSubstr("was built for plugin ABI 4 (before plan); this hsad needs ABI " +
                                  std::to_string(HSA_PLUGIN_ABI_VERSION) + ": rebuild it"));
}

TEST(PluginLoader, ReportsThePluginsOwnConfigureError) {
  const toml::table settings;
  const PluginError e = expect_plugin_error(
      [&] { (void)fixture_loader().load_driver("dev", "fixture_configure_fails", settings); });
  EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
  EXPECT_EQ(e.plugin(), "fixture_configure_fails");
  EXPECT_THAT(e.what(), HasSubstr("driver 'dev' (plugin fixture_configure_fails)"));
  EXPECT_THAT(e.what(), HasSubstr("cannot open /dev/fixture0: no such device"));
}

TEST(PluginLoader, ConfigureErrorNamesTheOffendingKey) {
  const toml::table settings = toml::parse("fail_read_after = \"soon\"");
  const PluginError e = expect_plugin_error(
      [&] { (void)fixture_loader().load_driver("loop", "fixture_loopback", settings); });
  EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
  EXPECT_THAT(e.what(), HasSubstr("fail_read_after: expected an integer >= -1, got \"soon\""));
}

TEST(PluginLoader, LoadDriverReturnsAConfiguredDriver) {
  const auto driver = fixture_loader().load_driver("loop", "fixture_loopback", toml::table{});
  EXPECT_EQ(driver->name(), "loop");
  EXPECT_EQ(driver->state(), DriverState::inactive);
  EXPECT_EQ(driver->channels().size(), 5u);
}

TEST(PluginLoader, DefaultDirectoriesStartWithThoseFromTheEnvironment) {
  ASSERT_EQ(setenv("HSA_PLUGIN_PATH", "/opt/a::/opt/b", 1), 0);
  const auto dirs = default_plugin_dirs();
  unsetenv("HSA_PLUGIN_PATH");
  ASSERT_GE(dirs.size(), 3u);
  EXPECT_EQ(dirs[0], "/opt/a");
  EXPECT_EQ(dirs[1], "/opt/b");
  EXPECT_EQ(dirs[2], HSA_PLUGIN_DIR);  // this test runs from the build tree
}

// An installed hsad never loads a build tree's plugins: only a program inside the tree does.
TEST(PluginLoader, OnlyAProgramInsideTheBuildTreeSearchesItsPlugins) {
  EXPECT_TRUE(running_from_build_tree());
  EXPECT_TRUE(path_is_within("/src/hsa/build", "/src/hsa/build/bin/hsad"));
  EXPECT_TRUE(path_is_within("/src/hsa/build/", "/src/hsa/build/bin/hsad"));
  EXPECT_FALSE(path_is_within("/src/hsa/build", "/usr/bin/hsad"));
  EXPECT_FALSE(path_is_within("/src/hsa/build", "/src/hsa/build2/bin/hsad"));
  EXPECT_FALSE(path_is_within("/src/hsa/build", "/src/hsa/build"));
}

}  // namespace
}  // namespace hsa::io
