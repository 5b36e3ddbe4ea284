// The driver lifecycle as the framework enforces it, on the loopback fixture plugin, and the
// recovery from a failed read or write on a scripted driver built into this test (an in-process
// "plugin": a descriptor of its own and a dlopen handle of the test program itself), whose every
// lifecycle step can be told to fail.
#include "drivers/driver_handle.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <toml++/toml.h>

#include "drivers/plugin_abi.hpp"
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
  EXPECT_FALSE(driver->recover(toml::table{}).ok());

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
  const toml::table settings = toml::parse("fail_read_after = 2");
  auto driver = make_loopback();
  ASSERT_TRUE(driver->configure(settings).ok());
  ASSERT_TRUE(driver->activate().ok());
  const ChannelSlot* slots_before = driver->slots().data();
  EXPECT_EQ(driver->read(0ns, period), IoStatus::ok);
  EXPECT_EQ(driver->read(period, period), IoStatus::ok);
  EXPECT_EQ(driver->read(2 * period, period), IoStatus::error);
  EXPECT_EQ(driver->state(), DriverState::error);
  // In error nothing reaches the driver, not even a write.
  EXPECT_EQ(driver->write(2 * period, period), IoStatus::error);
  EXPECT_FALSE(driver->activate().ok());

  // Recovery brings it back to where it failed, with the same slots (bound signals stay valid).
  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(driver->state(), DriverState::active);
  EXPECT_EQ(driver->slots().data(), slots_before);
  ASSERT_EQ(driver->channels().size(), 5u);
  EXPECT_EQ(driver->channels()[0].name, "enc");
  const auto ao = *driver->find_channel("ao");
  const auto ai = *driver->find_channel("ai");
  driver->slots()[ao].value = 1.25;
  EXPECT_EQ(driver->write(3 * period, period), IoStatus::ok);
  EXPECT_EQ(driver->read(3 * period, period), IoStatus::ok);
  EXPECT_EQ(driver->slots()[ai].value, 1.25);
  // The reconfigured fixture counts its reads from 0 again: it fails after two more, and a
  // second recovery works like the first.
  EXPECT_EQ(driver->read(4 * period, period), IoStatus::ok);
  EXPECT_EQ(driver->read(5 * period, period), IoStatus::error);
  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(driver->read(6 * period, period), IoStatus::ok);
}

// The fixture counts make_safe calls in a function it exports: the library make_loopback loaded.
std::uint64_t loopback_make_safe_calls() {
  void* lib = dlopen(HSA_FIXTURE_LOOPBACK_PATH, RTLD_NOW | RTLD_NOLOAD);
  if (lib == nullptr) return UINT64_MAX;
  using Count = std::uint64_t (*)();
  const auto count = reinterpret_cast<Count>(dlsym(lib, "fixture_loopback_make_safe_calls"));
  const std::uint64_t n = count != nullptr ? count() : UINT64_MAX;
  dlclose(lib);
  return n;
}

TEST(DriverHandle, MakeSafeReachesAPluginDriverThatFailedAndSaysWhy) {
  auto driver = make_loopback();
  ASSERT_TRUE(driver->configure(toml::parse("fail_read_after = 0")).ok());
  ASSERT_TRUE(driver->activate().ok());
  const auto ao = *driver->find_channel("ao");
  driver->slots()[ao].value = 2.0;
  ASSERT_EQ(driver->write(0ns, period), IoStatus::ok);
  ASSERT_EQ(driver->read(period, period), IoStatus::error);
  ASSERT_EQ(driver->state(), DriverState::error);
  EXPECT_EQ(driver->failure_reason(), "read failed: fixture read failure injected");

  const std::uint64_t before = loopback_make_safe_calls();
  ASSERT_NE(before, UINT64_MAX) << "fixture_loopback_make_safe_calls not found";
  driver->make_safe();
  EXPECT_EQ(loopback_make_safe_calls(), before + 1);
  EXPECT_EQ(driver->state(), DriverState::error);
  // The echo of the output is at its safe value once recovered (recovery keeps the driver's
  // object; make_safe had zeroed it, the slot still holds 2.0 until the next write).
  ASSERT_TRUE(driver->recover(toml::table{}).ok());
  ASSERT_EQ(driver->read(2 * period, period), IoStatus::ok);
  EXPECT_EQ(driver->slots()[*driver->find_channel("ai")].value, 0.0);
}

TEST(DriverHandle, MakeSafeIsANoOpOnAnUnconfiguredDriver) {
  auto driver = make_loopback();
  const std::uint64_t before = loopback_make_safe_calls();
  driver->make_safe();
  EXPECT_EQ(loopback_make_safe_calls(), before);
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

// --- Recovery, on a scripted driver ------------------------------------------------------------

// What the scripted driver is told to do, and what it saw. One per test (g_script).
struct Script {
  std::atomic<bool> fail_io{false};  // read and write return error
  // With fail_io: read reports an earlier write the device refused (a bus thread's write).
  std::atomic<bool> fail_as_write{false};
  bool fail_on_error = false;
  int configure_failures = 0;  // the next N on_configure calls fail
  int activate_failures = 0;   // the next N on_activate calls fail
  bool declare_other_channels = false;
  int on_error_calls = 0, on_configure_calls = 0, on_activate_calls = 0, on_cleanup_calls = 0;
  // Set for the length of every lifecycle step; a read or write that sees it is an overlap.
  std::atomic<bool> in_lifecycle{false};
  std::atomic<int> io_calls{0};
  std::atomic<int> io_during_lifecycle{0};
  std::atomic<int> make_safe_calls{0};
  std::atomic<int> make_safe_during_lifecycle{0};
};
Script* g_script = nullptr;

class ScriptedDriver final : public Driver {
 public:
  Result check_settings(const toml::table&) const override { return Result::success(); }
  Result plan(const toml::table&, DriverPlan&) const override { return Result::success(); }
  Result on_configure(const toml::table&) override {
    const Step step(*g_script);
    ++g_script->on_configure_calls;
    if (g_script->configure_failures > 0) {
      --g_script->configure_failures;
      return Result::failure("bus does not answer");
    }
    channels_ = {{"in", ChannelKind::analog_input, "V"}, {"out", ChannelKind::analog_output, "V"}};
    if (g_script->declare_other_channels) channels_[1].unit = "A";
    return Result::success();
  }
  std::span<const ChannelInfo> channels() const override { return channels_; }
  Result on_activate() override {
    const Step step(*g_script);
    ++g_script->on_activate_calls;
    if (g_script->activate_failures > 0) {
      --g_script->activate_failures;
      return Result::failure("amplifier refuses power");
    }
    return Result::success();
  }
  Result on_cleanup() override {
    const Step step(*g_script);
    ++g_script->on_cleanup_calls;
    channels_.clear();
    return Result::success();
  }
  Result on_error() override {
    const Step step(*g_script);
    ++g_script->on_error_calls;
    channels_.clear();
    return g_script->fail_on_error ? Result::failure("bus gone for good") : Result::success();
  }
  IoStatus read(Timestamp t, Duration, std::span<ChannelSlot> slots) noexcept override {
    if (!io()) return g_script->fail_as_write ? IoStatus::write_error : IoStatus::error;
    slots[0] = {slots[1].value, t, SampleStatus::ok};  // echoes the output
    return IoStatus::ok;
  }
  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot>) noexcept override {
    return io() ? IoStatus::ok : IoStatus::error;
  }
  void make_safe() noexcept override {
    g_script->make_safe_calls.fetch_add(1);
    if (g_script->in_lifecycle) g_script->make_safe_during_lifecycle.fetch_add(1);
  }
  std::string_view failure_reason() const noexcept override {
    if (!g_script->fail_io) return "";
    return g_script->fail_as_write ? "Modbus exception 3 writing holding registers 0..1"
                                   : "Modbus exception 2 reading input registers 0..1";
  }

 private:
  // Marks a lifecycle step; sleeps a little so that an RT thread racing it would be seen.
  struct Step {
    explicit Step(Script& s) : script(s) { script.in_lifecycle = true; }
    ~Step() {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      script.in_lifecycle = false;
    }
    Script& script;
  };
  bool io() noexcept {
    g_script->io_calls.fetch_add(1);
    if (g_script->in_lifecycle) g_script->io_during_lifecycle.fetch_add(1);
    return !g_script->fail_io;
  }
  std::vector<ChannelInfo> channels_;
};

const hsa_plugin_descriptor scripted_descriptor{
    HSA_PLUGIN_ABI_VERSION, "scripted", []() -> Driver* { return new ScriptedDriver(); },
    [](Driver* driver) { delete driver; }};

class DriverHandleRecovery : public ::testing::Test {
 protected:
  void SetUp() override {
    g_script = &script;
    // dlopen(nullptr) is the test program itself: the Plugin's dlclose then only drops a count.
    auto plugin = std::make_shared<const Plugin>(dlopen(nullptr, RTLD_NOW), scripted_descriptor,
                                                 "(in-process)");
    driver = std::make_unique<DriverHandle>("bus", std::move(plugin));
    ASSERT_TRUE(driver->configure(settings).ok());
    ASSERT_TRUE(driver->activate().ok());
  }
  void TearDown() override {
    driver.reset();
    g_script = nullptr;
  }
  // One RT cycle as the daemon runs it: read, then write.
  IoStatus cycle() {
    const IoStatus r = driver->read(t, period);
    const IoStatus w = driver->write(t, period);
    t += period;
    return r == IoStatus::ok && w == IoStatus::ok ? IoStatus::ok : IoStatus::error;
  }
  void fail_once() {
    script.fail_io = true;
    ASSERT_EQ(cycle(), IoStatus::error);
    ASSERT_EQ(driver->state(), DriverState::error);
    script.fail_io = false;
  }

  Script script;
  toml::table settings;
  std::unique_ptr<DriverHandle> driver;
  Timestamp t{};
};

TEST_F(DriverHandleRecovery, InErrorTheRtCallsDoNotReachTheDriver) {
  fail_once();
  const int calls = script.io_calls;
  for (int i = 0; i < 10; ++i) EXPECT_EQ(cycle(), IoStatus::error);
  EXPECT_EQ(script.io_calls, calls);
  EXPECT_EQ(script.on_error_calls, 0);  // and the RT calls run no lifecycle step
}

TEST_F(DriverHandleRecovery, MakeSafeReachesADriverInError) {
  fail_once();
  EXPECT_EQ(script.make_safe_calls, 0);
  driver->make_safe();
  EXPECT_EQ(script.make_safe_calls, 1);
  EXPECT_EQ(driver->state(), DriverState::error);  // make_safe changes no state
  EXPECT_EQ(script.on_error_calls, 0);             // and runs no lifecycle step
}

TEST_F(DriverHandleRecovery, TheFailureReasonNamesTheStepAndTheDevicesCause) {
  EXPECT_EQ(driver->failure_reason(), "");  // not failed: nothing to say
  fail_once();
  EXPECT_EQ(driver->failure_reason(), "read failed: Modbus exception 2 reading input registers 0..1");
}

// A write refused on the driver's own thread is found at the next read, and is still a write's.
TEST_F(DriverHandleRecovery, AWriteFailureFoundAtTheReadIsNamedAWrite) {
  script.fail_as_write = true;
  fail_once();
  EXPECT_EQ(driver->failure_reason(), "write failed: Modbus exception 3 writing holding registers 0..1");
}

TEST_F(DriverHandleRecovery, MakeSafeStopsReachingTheDriverOnceARecoveryReleasesIt) {
  fail_once();
  script.configure_failures = 1;  // the recovery stops after on_error, with the driver released
  EXPECT_FALSE(driver->recover(settings).ok());
  driver->make_safe();
  EXPECT_EQ(script.make_safe_calls, 0);
  ASSERT_TRUE(driver->recover(settings).ok());
  driver->make_safe();  // handed back: it reaches the driver again
  EXPECT_EQ(script.make_safe_calls, 1);
}

TEST_F(DriverHandleRecovery, DestroyingADriverInErrorMakesItSafeFirst) {
  fail_once();
  driver.reset();
  EXPECT_EQ(script.make_safe_calls, 1);
  EXPECT_EQ(script.on_error_calls, 1);
}

TEST_F(DriverHandleRecovery, RunsOnErrorConfigureActivateAndKeepsTheSlots) {
  driver->slots()[1].value = 3.0;
  ASSERT_EQ(cycle(), IoStatus::ok);
  const ChannelSlot* slots = driver->slots().data();
  fail_once();
  driver->slots()[1].value = 0.5;  // the loop's safe output, written while the driver is out

  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(driver->state(), DriverState::active);
  EXPECT_EQ(script.on_error_calls, 1);
  EXPECT_EQ(script.on_configure_calls, 2);
  EXPECT_EQ(script.on_activate_calls, 2);
  EXPECT_EQ(driver->slots().data(), slots);
  ASSERT_EQ(cycle(), IoStatus::ok);
  EXPECT_EQ(driver->slots()[0].value, 0.5);
}

TEST_F(DriverHandleRecovery, AFailedConfigureStaysInErrorAndALaterCallResumesThere) {
  fail_once();
  script.configure_failures = 1;
  const Result r = driver->recover(settings);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr("driver 'bus' (plugin scripted): recovery: bus does not answer"));
  EXPECT_EQ(driver->state(), DriverState::error);
  EXPECT_EQ(cycle(), IoStatus::error);

  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(script.on_error_calls, 1);  // released once: the retry starts at on_configure
  EXPECT_EQ(script.on_configure_calls, 3);
  EXPECT_EQ(cycle(), IoStatus::ok);
}

TEST_F(DriverHandleRecovery, AFailedActivateStaysInErrorAndALaterCallOnlyActivates) {
  fail_once();
  script.activate_failures = 1;
  const Result r = driver->recover(settings);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr("recovery: amplifier refuses power"));
  EXPECT_EQ(driver->state(), DriverState::error);
  EXPECT_EQ(cycle(), IoStatus::error);

  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(script.on_configure_calls, 2);
  EXPECT_EQ(script.on_activate_calls, 3);
  EXPECT_EQ(cycle(), IoStatus::ok);
}

TEST_F(DriverHandleRecovery, RefusesADriverThatDeclaresOtherChannels) {
  fail_once();
  const ChannelSlot* slots = driver->slots().data();
  script.declare_other_channels = true;
  const Result r = driver->recover(settings);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr("channel 1 is 'out' (analog output, A) after recovery, "
                                     "'out' (analog output, V) before"));
  EXPECT_EQ(driver->state(), DriverState::error);
  EXPECT_EQ(script.on_cleanup_calls, 1);  // left unconfigured for the next attempt
  EXPECT_EQ(driver->slots().data(), slots);
  EXPECT_EQ(driver->channels()[1].unit, "V");

  script.declare_other_channels = false;
  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(cycle(), IoStatus::ok);
}

TEST_F(DriverHandleRecovery, AFailedOnErrorFinalizesTheDriver) {
  fail_once();
  script.fail_on_error = true;
  const Result r = driver->recover(settings);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(r.message(), HasSubstr("recovery failed, driver finalized: bus gone for good"));
  EXPECT_EQ(driver->state(), DriverState::finalized);
  EXPECT_FALSE(driver->recover(settings).ok());
  EXPECT_EQ(script.on_error_calls, 1);
  EXPECT_EQ(cycle(), IoStatus::error);
}

TEST_F(DriverHandleRecovery, ADriverThatFailedWhileInactiveComesBackInactive) {
  ASSERT_TRUE(driver->deactivate().ok());
  script.fail_io = true;
  EXPECT_EQ(driver->read(t, period), IoStatus::error);
  script.fail_io = false;
  ASSERT_EQ(driver->state(), DriverState::error);
  ASSERT_TRUE(driver->recover(settings).ok());
  EXPECT_EQ(driver->state(), DriverState::inactive);
  EXPECT_EQ(script.on_activate_calls, 1);  // the one of SetUp only
}

TEST_F(DriverHandleRecovery, DestroyingADriverInErrorReleasesIt) {
  fail_once();
  driver.reset();
  EXPECT_EQ(script.on_error_calls, 1);
}

// The RT thread keeps cycling while a normal thread recovers the driver, as in hsad: no read or
// write may reach the driver while a lifecycle step runs, and once recover() returns the RT
// thread gets through to the driver again.
template <typename Predicate>
void wait_until(Predicate done) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!done() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
}

TEST_F(DriverHandleRecovery, TheRtThreadNeverRunsTheDriverDuringALifecycleStep) {
  fail_once();
  std::atomic<bool> stop{false};
  std::atomic<int> ok_cycles{0};
  std::thread rt([&] {
    Timestamp rt_t{};
    while (!stop.load()) {
      const IoStatus r = driver->read(rt_t, period);
      const IoStatus w = driver->write(rt_t, period);
      if (r == IoStatus::ok && w == IoStatus::ok) ok_cycles.fetch_add(1);
      driver->make_safe();  // as hsad does for a failed driver: it must not race a recovery
      rt_t += period;
    }
  });
  for (int round = 0; round < 20; ++round) {
    script.configure_failures = round % 3 == 0 ? 1 : 0;  // some rounds need a second attempt
    Result r = driver->recover(settings);
    if (!r) r = driver->recover(settings);
    ASSERT_TRUE(r.ok()) << r.message();
    // Wait (bounded) for the RT thread to get through, then make the driver fail again.
    const int before = ok_cycles.load();
    wait_until([&] { return ok_cycles.load() > before; });
    script.fail_io = true;
    wait_until([&] { return driver->state() == DriverState::error; });
    script.fail_io = false;
    ASSERT_EQ(driver->state(), DriverState::error);
  }
  stop = true;
  rt.join();
  EXPECT_GT(ok_cycles.load(), 0);
  EXPECT_EQ(script.io_during_lifecycle.load(), 0);
  EXPECT_GT(script.make_safe_calls.load(), 0);
  EXPECT_EQ(script.make_safe_during_lifecycle.load(), 0);
}

}  // namespace
}  // namespace hsa::io
