// Each plugin's plan (Driver::plan, driver_plan.hpp): the devices it states from its settings, with
// its own defaults applied so that two spellings of one device are one key, and the channels it
// would declare; a refusal as check_settings refuses. The settings are the shipped examples'
// (systemd/*.toml), changed key by key; nothing is opened.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <toml++/toml.h>

#include "drivers/plugin_loader.hpp"

namespace hsa::io {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

// The settings of the driver of `plugin` in a shipped example configuration.
toml::table example_settings(const std::string& file, const std::string& plugin) {
  const toml::table config = toml::parse_file(std::string(HSA_SOURCE_DIR) + "/systemd/" + file);
  for (const toml::node& d : *config["drivers"].as_array()) {
    if (d.as_table()->at("plugin").value<std::string>() == plugin) return *d.as_table()->at("settings").as_table();
  }
  ADD_FAILURE() << file << " has no driver of plugin " << plugin;
  return {};
}

// The plan of `plugin` for `settings`; `refusal` gets the plugin's message when it refuses.
DriverPlan plan_of(const std::string& plugin, const toml::table& settings, std::string* refusal = nullptr) {
  const PluginLoader loader(default_plugin_dirs());
  const auto loaded = loader.load(plugin);
  const std::unique_ptr<Driver, void (*)(Driver*)> driver(loaded->descriptor().create(), loaded->descriptor().destroy);
  DriverPlan plan;
  const Result r = driver->plan(settings, plan);
  if (refusal != nullptr) *refusal = r.ok() ? "" : r.message();
  EXPECT_TRUE(r.ok() || refusal != nullptr) << r.message();
  return plan;
}

std::vector<std::string> channel_names(const DriverPlan& plan) {
  std::vector<std::string> names;
  for (const ChannelInfo& c : plan.channels) names.push_back(c.name);
  return names;
}

TEST(ModbusPlan, ATcpDeviceIsHostAndPortWithTheDefault502) {
  toml::table settings = example_settings("hsad-modbus-simdev.toml", "modbus");
  EXPECT_THAT(plan_of("modbus", settings).devices, ElementsAre("modbus-tcp:127.0.0.1:1502"));
  settings.erase("port");
  EXPECT_THAT(plan_of("modbus", settings).devices, ElementsAre("modbus-tcp:127.0.0.1:502"));
  settings.insert_or_assign("port", 502);
  EXPECT_THAT(plan_of("modbus", settings).devices, ElementsAre("modbus-tcp:127.0.0.1:502"));
}

TEST(ModbusPlan, ASerialDeviceIsItsResolvedPath) {
  toml::table settings = example_settings("hsad-modbus-simdev.toml", "modbus");
  settings.erase("host");
  settings.erase("port");
  settings.insert_or_assign("transport", "rtu");
  settings.insert_or_assign("device", "/dev/../dev/null");  // a device that exists, spelled the long way
  EXPECT_THAT(plan_of("modbus", settings).devices, ElementsAre("serial:/dev/null"));
}

TEST(ModbusPlan, TheChannelsAreTheMappedOnesThenTheLinksOwn) {
  const DriverPlan plan = plan_of("modbus", example_settings("hsad-modbus-simdev.toml", "modbus"));
  EXPECT_THAT(channel_names(plan), ElementsAre("encoder", "pressure_a", "pressure_b", "opening_cmd", "valve_enable",
                                               "estop", "link_up", "link_errors", "transaction_errors",
                                               "output_timeouts"));
}

TEST(ModbusPlan, BadSettingsAreRefusedAsCheckSettingsRefusesThem) {
  toml::table settings = example_settings("hsad-modbus-simdev.toml", "modbus");
  settings.insert_or_assign("port", 70000);
  std::string refusal;
  (void)plan_of("modbus", settings, &refusal);
  EXPECT_THAT(refusal, ::testing::HasSubstr("port"));
}

TEST(SocketCanPlan, TheDeviceIsTheInterface) {
  toml::table settings = example_settings("hsad-socketcan.toml", "socketcan");
  const DriverPlan plan = plan_of("socketcan", settings);
  EXPECT_THAT(plan.devices, ElementsAre("can:vcan0"));
  EXPECT_THAT(channel_names(plan), ::testing::Contains("bus_off"));
  settings.insert_or_assign("interface", "can1");
  EXPECT_THAT(plan_of("socketcan", settings).devices, ElementsAre("can:can1"));
}

TEST(GpiodPlan, EachChipOnceWhateverItsSpelling) {
  toml::table settings = example_settings("hsad-gpiod.toml", "gpiod");
  const DriverPlan plan = plan_of("gpiod", settings);
  EXPECT_THAT(plan.devices, ElementsAre("gpiochip:gpiochip0")) << "every channel on the default chip: one device";
  EXPECT_THAT(channel_names(plan), ::testing::Contains("estop"));
  for (const char* spelling : {"0", "/dev/gpiochip0", "gpiochip0"}) {
    settings.insert_or_assign("chip", spelling);
    EXPECT_THAT(plan_of("gpiod", settings).devices, ElementsAre("gpiochip:gpiochip0")) << spelling;
  }
  settings.insert_or_assign("chip", "gpio-sim.0-node0");  // a label stays a label
  EXPECT_THAT(plan_of("gpiod", settings).devices, ElementsAre("gpiochip:gpio-sim.0-node0"));
}

TEST(SimPlan, TheSimulatedRigOpensNoDeviceAndDeclaresItsChannels) {
  const DriverPlan plan = plan_of("sim", example_settings("hsad-sim.toml", "sim"));
  EXPECT_THAT(plan.devices, IsEmpty());
  EXPECT_THAT(channel_names(plan), ::testing::Contains("estop"));
}

}  // namespace
}  // namespace hsa::io
