// The driver lifecycle as the framework enforces it, on the loopback fixture plugin.
#include "drivers/driver_handle.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>

#include <toml++/toml.h>

#include "drivers/plugin_loader.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr Duration period = 100us;

std::unique_ptr<DriverHandle> make_loopback() {
  return std::make_unique<DriverHandle>("loop",
                                        PluginLoader({}).load(HSA_FIXTURE_LOOPBACK_PATH));
}

TEST(DriverHandle, ConfigureDeclaresChannelsAndAllocatesOneSlotEach) {
  auto driver = make_loopback();
  EXPECT_EQ(driver->state(), DriverState::unconfigured);
  EXPECT_TRUE(driver->slots().empty());

  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  EXPECT_EQ(driver->state(), DriverState::inactive);
  ASSERT_EQ(driver->channels().size(), 5u);
  EXPECT_EQ(driver->slots().size(), 5u);
  EXPECT_EQ(driver->channels()[0].name, "enc");
  EXPECT_EQ(driver->channels()[0].kind, ChannelKind::encoder_input);
  EXPECT_EQ(driver->channels()[2].kind, ChannelKind::analog_output);
  EXPECT_EQ(driver->find_channel("di"), 3u);
  EXPECT_FALSE(driver->find_channel("nope").has_value());
}

TEST(DriverHandle, WalksTheLifecycleForwardAndBack) {
  auto driver = make_loopback();
  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  ASSERT_TRUE(driver->activate().ok());
  EXPECT_EQ(driver->state(), DriverState::active);
  ASSERT_TRUE(driver->deactivate().ok());
  EXPECT_EQ(driver->state(), DriverState::inactive);
  ASSERT_TRUE(driver->cleanup().ok());
  EXPECT_EQ(driver->state(), DriverState::unconfigured);
  EXPECT_TRUE(driver->channels().empty());
  // and may be configured again
  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  EXPECT_EQ(driver->channels().size(), 5u);
}

TEST(DriverHandle, RefusesOutOfOrderTransitionsWithAMessage) {
  auto driver = make_loopback();
  const Result r = driver->activate();
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(),
              HasSubstr("driver 'loop' (plugin fixture_loopback): cannot activate while "
                        "unconfigured"));
  EXPECT_EQ(driver->state(), DriverState::unconfigured);
  EXPECT_FALSE(driver->deactivate().ok());
  EXPECT_FALSE(driver->recover().ok());

  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  EXPECT_FALSE(driver->configure(toml::table{}).ok());
  EXPECT_EQ(driver->state(), DriverState::inactive);
}

TEST(DriverHandle, ReadsWhenConfiguredAndWritesOnlyWhenActive) {
  auto driver = make_loopback();
  EXPECT_EQ(driver->read(0ns, period), IoStatus::error);  // unconfigured: driver not called

  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  EXPECT_EQ(driver->read(0ns, period), IoStatus::ok);
  EXPECT_EQ(driver->write(0ns, period), IoStatus::error);
  EXPECT_EQ(driver->state(), DriverState::inactive);  // a refused call is not a driver error

  ASSERT_TRUE(driver->activate().ok());
  EXPECT_EQ(driver->write(period, period), IoStatus::ok);
}

TEST(DriverHandle, ValuesTravelThroughTheSlotsAndThePlugin) {
  auto driver = make_loopback();
  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  ASSERT_TRUE(driver->activate().ok());
  const auto ai = *driver->find_channel("ai");
  const auto ao = *driver->find_channel("ao");

  driver->slots()[ao].value = 2.5;
  ASSERT_EQ(driver->write(0ns, period), IoStatus::ok);
  ASSERT_EQ(driver->read(period, period), IoStatus::ok);

  EXPECT_EQ(driver->slots()[ai].value, 2.5);
  EXPECT_EQ(driver->slots()[ai].timestamp, period);
  EXPECT_EQ(driver->slots()[ai].status, SampleStatus::ok);
}

TEST(DriverHandle, AFailedReadMovesToErrorUntilRecovered) {
  auto driver = make_loopback();
  ASSERT_TRUE(driver->configure(toml::parse("fail_read_after = 2")).ok());
  ASSERT_TRUE(driver->activate().ok());
  EXPECT_EQ(driver->read(0ns, period), IoStatus::ok);
  EXPECT_EQ(driver->read(period, period), IoStatus::ok);
  EXPECT_EQ(driver->read(2 * period, period), IoStatus::error);
  EXPECT_EQ(driver->state(), DriverState::error);
  // In error nothing reaches the driver, not even a write.
  EXPECT_EQ(driver->write(2 * period, period), IoStatus::error);
  EXPECT_FALSE(driver->activate().ok());

  ASSERT_TRUE(driver->recover().ok());
  EXPECT_EQ(driver->state(), DriverState::unconfigured);
  EXPECT_TRUE(driver->slots().empty());
  ASSERT_TRUE(driver->configure(toml::table{}).ok());
  EXPECT_EQ(driver->read(3 * period, period), IoStatus::ok);
}

TEST(DriverHandle, ReportsTheDriversOwnConfigureFailure) {
  auto driver =
      std::make_unique<DriverHandle>("dev", PluginLoader({}).load(HSA_FIXTURE_CONFIGURE_FAILS_PATH));
  const Result r = driver->configure(toml::table{});
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr("driver 'dev' (plugin fixture_configure_fails): cannot open"));
  EXPECT_EQ(driver->state(), DriverState::unconfigured);
}

TEST(DriverHandle, KeepsThePluginLoadedWhileTheDriverLives) {
  std::weak_ptr<const Plugin> weak;
  {
    auto plugin = PluginLoader({}).load(HSA_FIXTURE_LOOPBACK_PATH);
    weak = plugin;
    auto driver = std::make_unique<DriverHandle>("loop", std::move(plugin));
    EXPECT_FALSE(weak.expired());
    ASSERT_TRUE(driver->configure(toml::table{}).ok());
    ASSERT_TRUE(driver->activate().ok());
  }  // destroying an active driver deactivates, cleans up, then unloads
  EXPECT_TRUE(weak.expired());
}

}  // namespace
}  // namespace hsa::io
