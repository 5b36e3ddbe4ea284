// Scaling, limits, inversion and status as the framework applies them, and binding errors.
#include "drivers/signal_binding.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <toml++/toml.h>

#include "drivers/plugin_loader.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

// The channel is in SI already (its driver scaled it): the signal passes value and time through.
TEST(AnalogInput, PassesTheChannelsValueAndTimestampThrough) {
  const ChannelSlot slot{98e5, 7ms, SampleStatus::ok};
  const AnalogInput p(slot, {});
  const AnalogSample s = p.sample();
  EXPECT_DOUBLE_EQ(s.value, 98e5);
  EXPECT_EQ(s.timestamp, 7ms);
  EXPECT_EQ(s.status, SampleStatus::ok);
}

TEST(AnalogInput, OutsideTheLimitsIsOutOfRange) {
  ChannelSlot slot{0.0, 0ns, SampleStatus::ok};
  const AnalogInput x(slot, {.low_limit = 0.0, .high_limit = 0.3});
  slot.value = 0.3;  // on the limit is in range
  EXPECT_EQ(x.sample().status, SampleStatus::ok);
  slot.value = 0.301;
  EXPECT_EQ(x.sample().status, SampleStatus::out_of_range);
  EXPECT_DOUBLE_EQ(x.sample().value, 0.301);  // the value is still reported
  slot.value = -0.001;
  EXPECT_EQ(x.sample().status, SampleStatus::out_of_range);
  slot.value = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(x.sample().status, SampleStatus::out_of_range);
}

TEST(AnalogInput, TheDriversStatusWinsOverTheRangeCheck) {
  ChannelSlot slot{1e9, 0ns, SampleStatus::disconnected};
  const AnalogInput x(slot, {.high_limit = 1.0});
  EXPECT_EQ(x.sample().status, SampleStatus::disconnected);
  slot.status = SampleStatus::stale;
  EXPECT_EQ(x.sample().status, SampleStatus::stale);
}

TEST(AnalogOutput, ClampsToTheLimits) {
  ChannelSlot slot;
  AnalogOutput u(slot, {.low_limit = -1.0, .high_limit = 0.8});
  AnalogOutputState s = u.set(0.5);
  EXPECT_DOUBLE_EQ(slot.value, 0.5);
  EXPECT_DOUBLE_EQ(s.value, 0.5);
  EXPECT_FALSE(s.saturated);

  s = u.set(2.0);
  EXPECT_DOUBLE_EQ(slot.value, 0.8);
  EXPECT_DOUBLE_EQ(s.value, 0.8);  // what the channel gets
  EXPECT_TRUE(s.saturated);
  EXPECT_TRUE(u.state().saturated);

  s = u.set(-3.0);
  EXPECT_DOUBLE_EQ(slot.value, -1.0);
  EXPECT_TRUE(s.saturated);
}

TEST(AnalogOutput, DisabledOutputsZero) {
  ChannelSlot slot;
  AnalogOutput u(slot, {.enable = false});
  EXPECT_EQ(slot.value, 0.0);
  EXPECT_EQ(u.set(0.7).value, 0.0);
  EXPECT_EQ(slot.value, 0.0);
  u.set_enable(true);
  u.set(0.7);
  EXPECT_DOUBLE_EQ(slot.value, 0.7);
}

TEST(AnalogOutput, NonFiniteRequestOutputsZeroAndReportsSaturation) {
  ChannelSlot slot;
  AnalogOutput u(slot, {});
  u.set(0.5);
  ASSERT_EQ(slot.value, 0.5);
  const AnalogOutputState s = u.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(slot.value, 0.0);
  EXPECT_TRUE(s.saturated);
  u.set(std::numeric_limits<double>::infinity());
  EXPECT_EQ(slot.value, 0.0);
}

TEST(DigitalInput, InvertTurnsAnActiveLowLineIntoAssertedTrue) {
  ChannelSlot slot{1.0, 3ms, SampleStatus::ok};
  const DigitalInput straight(slot, {});
  const DigitalInput estop(slot, {.invert = true});
  EXPECT_TRUE(straight.sample().value);
  EXPECT_FALSE(estop.sample().value);
  slot.value = 0.0;
  EXPECT_FALSE(straight.sample().value);
  EXPECT_TRUE(estop.sample().value);
  EXPECT_EQ(estop.sample().timestamp, 3ms);
}

TEST(DigitalOutput, InvertFlipsTheRawLevel) {
  ChannelSlot a;
  ChannelSlot b;
  DigitalOutput plain(a, {});
  DigitalOutput inverted(b, {.invert = true});
  EXPECT_EQ(a.value, 0.0);
  EXPECT_EQ(b.value, 1.0);  // false on an inverted output drives the line high from binding on
  plain.set(true);
  inverted.set(true);
  EXPECT_EQ(a.value, 1.0);
  EXPECT_EQ(b.value, 0.0);
  EXPECT_TRUE(inverted.value());
}

class BindingToLoopback : public ::testing::Test {
 protected:
  void SetUp() override {
    driver_ = PluginLoader({}).load_driver("loop", HSA_FIXTURE_LOOPBACK_PATH, toml::table{});
  }
  std::unique_ptr<DriverHandle> driver_;
};

template <typename F>
BindingError expect_binding_error(F&& bind) {
  try {
    bind();
  } catch (const BindingError& e) {
    return e;
  }
  ADD_FAILURE() << "no BindingError thrown";
  return BindingError("", "", "", "");
}

TEST_F(BindingToLoopback, SignalsRoundTripThroughThePlugin) {
  AnalogOutput u = bind_analog_output("valve_cmd", *driver_, "ao");
  DigitalOutput enable = bind_digital_output("valve_enable", *driver_, "do");
  const AnalogInput v = bind_analog_input("valve_volts", *driver_, "ai");
  const DigitalInput enabled = bind_digital_input("valve_enabled", *driver_, "di");
  const AnalogInput count = bind_encoder_input("cycles", *driver_, "enc");
  ASSERT_TRUE(driver_->activate().ok());

  u.set(0.25);
  enable.set(true);
  ASSERT_EQ(driver_->write(0ns, 100us), IoStatus::ok);
  ASSERT_EQ(driver_->read(100us, 100us), IoStatus::ok);

  EXPECT_DOUBLE_EQ(v.sample().value, 0.25);
  EXPECT_TRUE(v.sample().ok());
  EXPECT_EQ(v.sample().timestamp, 100us);
  EXPECT_TRUE(enabled.sample().value);
  EXPECT_DOUBLE_EQ(count.sample().value, 1.0);  // one read: the fixture counts reads
}

TEST_F(BindingToLoopback, UnknownChannelNamesSignalDriverAndChannel) {
  const BindingError e =
      expect_binding_error([&] { (void)bind_analog_input("pressure_a", *driver_, "p_a"); });
  EXPECT_EQ(e.signal(), "pressure_a");
  EXPECT_EQ(e.driver(), "loop");
  EXPECT_EQ(e.channel(), "p_a");
  EXPECT_THAT(e.what(), HasSubstr("signal 'pressure_a'"));
  EXPECT_THAT(e.what(), HasSubstr("driver 'loop' (plugin fixture_loopback)"));
  EXPECT_THAT(e.what(), HasSubstr("channel 'p_a': no such channel"));
  EXPECT_THAT(e.what(), HasSubstr("enc, ai, ao, di, do"));
}

TEST_F(BindingToLoopback, WrongKindOrDirectionIsRefused) {
  BindingError e = expect_binding_error([&] { (void)bind_analog_output("cmd", *driver_, "ai"); });
  EXPECT_THAT(e.what(), HasSubstr("channel 'ai': kind mismatch: the signal is analog output, "
                                  "the channel is analog input (V)"));
  e = expect_binding_error([&] { (void)bind_analog_input("x", *driver_, "enc"); });
  EXPECT_THAT(e.what(), HasSubstr("the signal is analog input, the channel is encoder input"));
  e = expect_binding_error([&] { (void)bind_digital_input("estop", *driver_, "do"); });
  EXPECT_THAT(e.what(), HasSubstr("the signal is digital input, the channel is digital output"));
}

TEST_F(BindingToLoopback, NonsenseParametersAreRefused) {
  BindingError e = expect_binding_error(
      [&] { (void)bind_analog_output("cmd", *driver_, "ao", {.low_limit = 1, .high_limit = -1}); });
  EXPECT_THAT(e.what(), HasSubstr("signal 'cmd'"));
  EXPECT_THAT(e.what(), HasSubstr("low_limit (1.000000) is above high_limit (-1.000000)"));
}

TEST_F(BindingToLoopback, AnUnconfiguredDriverCannotBeBound) {
  ASSERT_TRUE(driver_->cleanup().ok());
  const BindingError e =
      expect_binding_error([&] { (void)bind_analog_input("p", *driver_, "ai"); });
  EXPECT_THAT(e.what(), HasSubstr("the driver is unconfigured"));
}

}  // namespace
}  // namespace hsa::io
