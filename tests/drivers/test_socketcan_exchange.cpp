// The socketcan plugin's frame bookkeeping, fed frames by hand as the driver feeds them from the
// socket: decoding into channels, wrong lengths rejected and counted, staleness from the cycle
// time, error frames and bus-off, output scheduling and safe values, and no allocation on the
// per-cycle path. The same behaviour is checked on a real kernel by test_socketcan_vcan.cpp.
#include <gtest/gtest.h>

#include <linux/can.h>
#include <linux/can/error.h>

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <vector>

#include <toml++/toml.h>

#include "drivers/socketcan/frame_exchange.hpp"
#include "tests/drivers/socketcan_test_frames.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::io::socketcan {
namespace {

using namespace std::chrono_literals;

// The tests' frame map (socketcan_test_frames.hpp), the encoder stale after 20 ms.
const std::string settings_text = socketcan_test::frame_map("interface = \"vcan0\"\n", 0.02);

enum Slot : std::size_t { encoder, temperature, current_cmd, enable, length_errors, error_frames, tx_dropped, bus_off,
            output_timeouts };

canfd_frame frame(canid_t id, std::initializer_list<std::uint8_t> data) {
  canfd_frame f{};
  f.can_id = id;
  f.len = static_cast<std::uint8_t>(data.size());
  if (data.size() > 0) std::memcpy(f.data, data.begin(), data.size());
  return f;
}

class SocketCanExchange : public ::testing::Test {
 protected:
  FrameExchange x{parse_can_settings(toml::parse(settings_text))};
  std::vector<ChannelSlot> slots = std::vector<ChannelSlot>(x.channels().size());
};

TEST_F(SocketCanExchange, DeclaresTheConfiguredChannelsThenTheStatusChannels) {
  const auto c = x.channels();
  ASSERT_EQ(c.size(), 9u);
  EXPECT_EQ(c[encoder].name, "encoder");
  EXPECT_EQ(c[encoder].unit, "m");
  EXPECT_EQ(c[current_cmd].kind, ChannelKind::analog_output);
  EXPECT_EQ(c[enable].kind, ChannelKind::digital_output);
  EXPECT_EQ(c[length_errors].name, "length_errors");
  EXPECT_EQ(c[error_frames].name, "error_frames");
  EXPECT_EQ(c[tx_dropped].name, "tx_dropped");
  EXPECT_EQ(c[bus_off].name, "bus_off");
  EXPECT_EQ(c[bus_off].kind, ChannelKind::digital_input);
  EXPECT_EQ(c[output_timeouts].name, "output_timeouts");
  EXPECT_EQ(c[output_timeouts].kind, ChannelKind::analog_input);
}

TEST_F(SocketCanExchange, OutputTimeoutsReachTheirStatusSlot) {
  x.fill_inputs(Timestamp{0}, slots);
  EXPECT_EQ(slots[output_timeouts].value, 0.0);
  x.count_output_timeout();
  x.count_output_timeout();
  x.fill_inputs(Timestamp{0}, slots);
  EXPECT_EQ(slots[output_timeouts].value, 2.0);
}

TEST_F(SocketCanExchange, InputsAreDisconnectedUntilTheirFirstFrame) {
  x.fill_inputs(5ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::disconnected);
  EXPECT_EQ(slots[temperature].status, SampleStatus::disconnected);
  EXPECT_EQ(slots[length_errors].status, SampleStatus::ok);
  EXPECT_EQ(slots[length_errors].value, 0.0);
}

TEST_F(SocketCanExchange, DecodesAValidFrameIntoItsChannelsStampedWithTheCycle) {
  x.accept(frame(0x181, {0xC0, 0x1D, 0xFE, 0xFF}), false, 7ms);  // -123456 µm
  x.accept(frame(0x18FF0001 | CAN_EFF_FLAG, {0x01, 0x2C}), false, 7ms);  // 300 * 0.1
  x.fill_inputs(8ms, slots);
  EXPECT_DOUBLE_EQ(slots[encoder].value, -0.123456);
  EXPECT_EQ(slots[encoder].status, SampleStatus::ok);
  EXPECT_EQ(slots[encoder].timestamp, 7ms);
  EXPECT_DOUBLE_EQ(slots[temperature].value, 30.0);
  EXPECT_EQ(slots[temperature].status, SampleStatus::ok);
  // The latest frame of an id wins.
  x.accept(frame(0x181, {0x40, 0x42, 0x0F, 0x00}), false, 9ms);  // 1000000 µm
  x.fill_inputs(9ms, slots);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 1.0);
  EXPECT_EQ(slots[encoder].timestamp, 9ms);
}

TEST_F(SocketCanExchange, AStandardAndAnExtendedFrameWithTheSameNumberAreDifferentFrames) {
  x.accept(frame(0x181 | CAN_EFF_FLAG, {1, 2, 3, 4}), false, 1ms);
  x.accept(frame(0x18FF0001 & CAN_SFF_MASK, {1, 2}), false, 1ms);
  x.fill_inputs(1ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::disconnected);
  EXPECT_EQ(slots[temperature].status, SampleStatus::disconnected);
  EXPECT_EQ(slots[length_errors].value, 0.0);
}

TEST_F(SocketCanExchange, GoesStaleWhenFramesStopAndRecoversWithTheNextOne) {
  x.accept(frame(0x181, {0x10, 0, 0, 0}), false, 100ms);
  x.fill_inputs(120ms, slots);  // exactly max_age old: still fresh
  EXPECT_EQ(slots[encoder].status, SampleStatus::ok);
  x.fill_inputs(121ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::stale);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 16e-6);  // the last value, with its own timestamp
  EXPECT_EQ(slots[encoder].timestamp, 100ms);
  x.accept(frame(0x181, {0x20, 0, 0, 0}), false, 125ms);
  x.fill_inputs(125ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::ok);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 32e-6);
}

TEST_F(SocketCanExchange, RejectsAndCountsAFrameOfTheWrongLengthOrFormat) {
  x.accept(frame(0x181, {0x10, 0, 0, 0}), false, 10ms);
  x.accept(frame(0x181, {0xFF, 0xFF, 0xFF}), false, 11ms);  // 3 bytes instead of 4
  x.fill_inputs(11ms, slots);
  EXPECT_EQ(slots[length_errors].value, 1.0);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 16e-6);  // unchanged
  EXPECT_EQ(slots[encoder].timestamp, 10ms);
  EXPECT_EQ(slots[encoder].status, SampleStatus::stale);  // not ok although it is young
  x.accept(frame(0x181, {0xFF, 0xFF, 0xFF, 0xFF, 0xFF}), false, 12ms);  // 5 bytes
  x.accept(frame(0x181, {0xFF, 0xFF, 0xFF, 0xFF}), true, 12ms);  // right length, but CAN FD
  x.fill_inputs(12ms, slots);
  EXPECT_EQ(slots[length_errors].value, 3.0);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 16e-6);
  EXPECT_EQ(slots[encoder].status, SampleStatus::stale);
  EXPECT_EQ(slots[temperature].status, SampleStatus::disconnected);  // other frames untouched
  x.accept(frame(0x181, {0x20, 0, 0, 0}), false, 13ms);
  x.fill_inputs(13ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::ok);
  EXPECT_DOUBLE_EQ(slots[encoder].value, 32e-6);
}

TEST_F(SocketCanExchange, IgnoresRemoteFramesAndUnknownIds) {
  canfd_frame rtr = frame(0x181 | CAN_RTR_FLAG, {});
  rtr.len = 4;
  x.accept(rtr, false, 1ms);
  x.accept(frame(0x123, {1}), false, 1ms);
  x.fill_inputs(1ms, slots);
  EXPECT_EQ(slots[encoder].status, SampleStatus::disconnected);
  EXPECT_EQ(slots[length_errors].value, 0.0);
}

TEST_F(SocketCanExchange, CountsErrorFramesAndLatchesBusOffUntilRestarted) {
  x.accept(frame(CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_RX_WARNING, 0, 0, 0, 0, 0, 0}), false, 1ms);
  x.fill_inputs(1ms, slots);
  EXPECT_EQ(slots[error_frames].value, 1.0);
  EXPECT_EQ(slots[bus_off].value, 0.0);
  EXPECT_FALSE(x.bus_off());
  x.accept(frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0}), false, 2ms);
  x.fill_inputs(2ms, slots);
  EXPECT_TRUE(x.bus_off());
  EXPECT_EQ(x.last_error_class(), static_cast<std::uint32_t>(CAN_ERR_BUSOFF));
  EXPECT_EQ(slots[bus_off].value, 1.0);
  EXPECT_EQ(slots[error_frames].value, 2.0);
  x.accept(frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, {0, 0, 0, 0, 0, 0, 0, 0}), false, 3ms);
  EXPECT_FALSE(x.bus_off());
  EXPECT_EQ(x.error_frames(), 3u);
}

TEST_F(SocketCanExchange, SendsOutputsOnTheFirstWriteThenAtTheirPeriod) {
  ASSERT_EQ(x.output_count(), 1u);
  EXPECT_EQ(x.output_mtu(0), CAN_MTU);
  slots[current_cmd].value = 1.5;
  slots[enable].value = 1.0;
  const canfd_frame* f = x.due_output(0, 0ms, slots);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->can_id, 0x201u);
  EXPECT_EQ(f->len, 3);
  EXPECT_EQ(f->data[0], 0x05);  // 1500 mA big-endian
  EXPECT_EQ(f->data[1], 0xDC);
  EXPECT_EQ(f->data[2], 0x01);
  x.mark_sent(0, 0ms);
  EXPECT_EQ(x.due_output(0, 9ms, slots), nullptr);
  slots[current_cmd].value = -2.0;
  f = x.due_output(0, 10ms, slots);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->data[0], 0xF8);  // -2000 = 0xF830
  EXPECT_EQ(f->data[1], 0x30);
  // Refused by the socket (not marked sent): still due next cycle.
  x.count_tx_dropped();
  EXPECT_NE(x.due_output(0, 11ms, slots), nullptr);
  x.mark_sent(0, 11ms);
  EXPECT_EQ(x.due_output(0, 12ms, slots), nullptr);
  x.reset_outputs();  // a new activation sends at once
  EXPECT_NE(x.due_output(0, 12ms, slots), nullptr);
  x.fill_inputs(12ms, slots);
  EXPECT_EQ(slots[tx_dropped].value, 1.0);
}

TEST_F(SocketCanExchange, SafeFrameAndNaNCommandsCarryTheSafeValue) {
  const canfd_frame& safe = x.safe_output(0);
  EXPECT_EQ(safe.can_id, 0x201u);
  EXPECT_EQ(safe.len, 3);
  EXPECT_EQ(safe.data[0], 0xFF);  // -250 mA = 0xFF06
  EXPECT_EQ(safe.data[1], 0x06);
  EXPECT_EQ(safe.data[2], 0x00);  // enable off
  slots[current_cmd].value = std::numeric_limits<double>::quiet_NaN();
  slots[enable].value = 1.0;
  const canfd_frame* f = x.due_output(0, 0ms, slots);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->data[0], 0xFF);
  EXPECT_EQ(f->data[1], 0x06);
  EXPECT_EQ(f->data[2], 0x01);
}

TEST_F(SocketCanExchange, ThePerCycleCallsAllocateNothing) {
  const canfd_frame good = frame(0x181, {1, 2, 3, 4});
  const canfd_frame bad = frame(0x181, {1, 2});
  const canfd_frame error = frame(CAN_ERR_FLAG | CAN_ERR_PROT, {0, 0, 0, 0, 0, 0, 0, 0});
  const long before = hsa::test::process_allocations();
  for (int i = 0; i < 1000; ++i) {
    const Timestamp t = i * 1ms;
    x.accept(i % 7 == 0 ? bad : i % 11 == 0 ? error : good, false, t);
    x.fill_inputs(t, slots);
    slots[current_cmd].value = 0.001 * i;
    if (x.due_output(0, t, slots) != nullptr) x.mark_sent(0, t);
  }
  EXPECT_EQ(hsa::test::process_allocations() - before, 0);
  EXPECT_GT(x.length_errors(), 0u);
}

}  // namespace
}  // namespace hsa::io::socketcan
