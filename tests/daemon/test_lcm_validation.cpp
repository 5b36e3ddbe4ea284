// The LCM bridge's pure parts, without any network: validation of setpoints and commands, decoding,
// the URL, seq-gap counting, conversion to the LCM types, and the
// configuration checks the bridge makes before it opens LCM.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "daemon/lcm_bridge/lcm_bridge.hpp"
#include "daemon/lcm_bridge/lcm_url.hpp"
#include "daemon/lcm_bridge/message_conversion.hpp"
#include "daemon/lcm_bridge/message_validation.hpp"
#include "daemon/lcm_bridge/sender_seq_gaps.hpp"
#include "daemon/lcm_bridge/seq_gap_counter.hpp"

namespace hsa::daemon {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

const AxisLimits kLimits{0.0, 0.3, 0.5};

hsa::setpoint_t setpoint(double position, bool has_ff = false, double ff = 0.0) {
  hsa::setpoint_t s{};
  s.utime = 123;
  s.seq = 7;
  s.position_m = position;
  s.has_velocity_ff = has_ff;
  s.velocity_ff_m_s = ff;
  return s;
}

hsa::command_t command(std::int8_t kind) {
  hsa::command_t c{};
  c.utime = 456;
  c.seq = 3;
  c.command = kind;
  return c;
}

template <typename LcmType>
std::vector<std::uint8_t> encode(const LcmType& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

// --- setpoints -------------------------------------------------------------------------------------

TEST(LcmValidation, AcceptsSetpointInsideRangeAndCopiesIt) {
  const auto v = validate_setpoint(setpoint(0.15, true, -0.2), kLimits);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.utime, 123);
  EXPECT_EQ(v.msg.seq, 7u);
  EXPECT_DOUBLE_EQ(v.msg.target, 0.15);
  EXPECT_DOUBLE_EQ(v.msg.velocity_m_s, -0.2);
}

TEST(LcmValidation, RangeEndsAreInside) {
  EXPECT_TRUE(validate_setpoint(setpoint(0.0), kLimits).ok());
  EXPECT_TRUE(validate_setpoint(setpoint(0.3), kLimits).ok());
}

TEST(LcmValidation, RejectsNanAndInfPosition) {
  EXPECT_EQ(validate_setpoint(setpoint(kNaN), kLimits).reason, RejectReason::non_finite);
  EXPECT_EQ(validate_setpoint(setpoint(kInf), kLimits).reason, RejectReason::non_finite);
  EXPECT_EQ(validate_setpoint(setpoint(-kInf), kLimits).reason, RejectReason::non_finite);
}

TEST(LcmValidation, RejectsPositionOutsideRange) {
  EXPECT_EQ(validate_setpoint(setpoint(0.3000001), kLimits).reason, RejectReason::out_of_range);
  EXPECT_EQ(validate_setpoint(setpoint(-1e-9), kLimits).reason, RejectReason::out_of_range);
  EXPECT_EQ(validate_setpoint(setpoint(150.0), kLimits).reason, RejectReason::out_of_range);  // mm sent as m
}

TEST(LcmValidation, ChecksVelocityFeedForwardOnlyWhenUsed) {
  EXPECT_EQ(validate_setpoint(setpoint(0.1, true, kNaN), kLimits).reason, RejectReason::non_finite);
  EXPECT_EQ(validate_setpoint(setpoint(0.1, true, kInf), kLimits).reason, RejectReason::non_finite);
  EXPECT_EQ(validate_setpoint(setpoint(0.1, true, 0.6), kLimits).reason, RejectReason::out_of_range);
  // Unused feed-forward: ignored, and zeroed so nothing unchecked reaches the RT thread.
  const auto v = validate_setpoint(setpoint(0.1, false, kNaN), kLimits);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.velocity_m_s, 0.0);
}

TEST(LcmValidation, RejectedSetpointCarriesNoValue) {
  const auto v = validate_setpoint(setpoint(kNaN), kLimits);
  EXPECT_FALSE(v.ok());
  EXPECT_EQ(v.msg.target, 0.0);
}

TEST(LcmValidation, AxisLimitsValidity) {
  EXPECT_TRUE(kLimits.valid());
  EXPECT_TRUE((AxisLimits{-0.1, 0.1}).valid());  // default speed limit: none
  EXPECT_FALSE((AxisLimits{0.2, 0.1}).valid());
  EXPECT_FALSE((AxisLimits{0.1, 0.1}).valid());
  EXPECT_FALSE((AxisLimits{kNaN, 0.1}).valid());
  EXPECT_FALSE((AxisLimits{0.0, kInf}).valid());
  EXPECT_FALSE((AxisLimits{0.0, 0.1, 0.0}).valid());
  EXPECT_FALSE((AxisLimits{0.0, 0.1, kNaN}).valid());
}

// --- commands --------------------------------------------------------------------------------------

TEST(LcmValidation, AcceptsEachSimpleCommand) {
  EXPECT_EQ(validate_command(command(hsa::command_t::ENABLE)).msg.kind, CommandKind::enable);
  EXPECT_EQ(validate_command(command(hsa::command_t::DISABLE)).msg.kind, CommandKind::disable);
  const auto reset = validate_command(command(hsa::command_t::RESET));
  ASSERT_TRUE(reset.ok());
  EXPECT_EQ(reset.msg.kind, CommandKind::reset);
  EXPECT_EQ(reset.msg.seq, 0u);     // the axis numbers the commands it takes
  EXPECT_EQ(reset.msg.ticket, 0u);  // and the operator thread gives the ticket
}

// --- CAPTURE: what the wire says is checked here; the axis's ring judges the rest (capture_gate) ---

hsa::command_t capture(std::int8_t action) {
  hsa::command_t c = command(hsa::command_t::CAPTURE);
  c.capture_action = action;
  c.capture_pre_s = -1;
  c.capture_post_s = 0.25;
  return c;
}

TEST(LcmValidation, CaptureNowCarriesItsLengthsAndNothingOfACondition) {
  hsa::command_t c = capture(hsa::command_t::CAPTURE_NOW);
  c.capture_signal = "position_m";  // not read for a capture now
  c.capture_level = kNaN;
  const auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.kind, CommandKind::capture);
  EXPECT_EQ(v.msg.capture.action, CaptureAction::now);
  EXPECT_EQ(v.msg.capture.pre_s, -1.0);
  EXPECT_EQ(v.msg.capture.post_s, 0.25);
  EXPECT_EQ(v.msg.capture.signal[0], '\0');
  EXPECT_EQ(v.msg.capture.signal_index, -1);  // the operator thread resolves it
}

TEST(LcmValidation, CaptureArmCarriesTheCondition) {
  hsa::command_t c = capture(hsa::command_t::CAPTURE_ARM);
  c.capture_signal = "following_error_m";
  c.capture_level = 0.001;
  c.capture_below = true;
  c.capture_repeat = true;
  const auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.capture.action, CaptureAction::arm);
  EXPECT_STREQ(v.msg.capture.signal, "following_error_m");
  EXPECT_EQ(v.msg.capture.level, 0.001);
  EXPECT_EQ(v.msg.capture.crossing, Crossing::below);
  EXPECT_TRUE(v.msg.capture.repeat);
}

TEST(LcmValidation, CaptureRefusesNonFiniteNumbersAnUnknownActionAndAnOverlongSignal) {
  hsa::command_t c = capture(hsa::command_t::CAPTURE_ARM);
  c.capture_signal = "following_error_m";
  c.capture_level = kNaN;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.capture_level = 0.001;
  c.capture_pre_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.capture_pre_s = 0.1;
  c.capture_post_s = kNaN;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.capture_post_s = 0.1;
  c.capture_signal = std::string(kCaptureSignalSize, 'x');
  EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range);
  c.capture_signal = "";
  EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range);
  for (const std::int8_t action : {0, 4, -1}) {
    EXPECT_EQ(validate_command(capture(action)).reason, RejectReason::unknown) << int(action);
  }
}

TEST(LcmValidation, CaptureDisarmReadsNothingElse) {
  hsa::command_t c = capture(hsa::command_t::CAPTURE_DISARM);
  c.capture_pre_s = kNaN;
  const auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.capture.action, CaptureAction::disarm);
}

TEST(LcmValidation, RejectsUnknownCommand) {
  EXPECT_EQ(validate_command(command(0)).reason, RejectReason::unknown);
  EXPECT_EQ(validate_command(command(6)).reason, RejectReason::unknown);
  EXPECT_EQ(validate_command(command(-1)).reason, RejectReason::unknown);
}

TEST(LcmValidation, ModeCommand) {
  auto c = command(hsa::command_t::MODE);
  c.mode = hsa::command_t::MODE_POSITION;
  c.valve_opening = kNaN;  // unused in position mode
  auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.kind, CommandKind::set_mode);
  EXPECT_EQ(v.msg.mode, ControlMode::position);
  EXPECT_FALSE(v.msg.has_opening);
  EXPECT_EQ(v.msg.opening, 0.0);

  c.mode = hsa::command_t::MODE_VALVE_OPENING;
  c.valve_opening = -0.25;
  v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.mode, ControlMode::open_loop);
  EXPECT_TRUE(v.msg.has_opening);
  EXPECT_DOUBLE_EQ(v.msg.opening, -0.25);

  EXPECT_EQ(v.msg.opening_duration_s, 0.0);  // none given: the setpoint timeout ends it

  // A duration the axis times itself, within [0, kMaxOpeningDurationS].
  c.opening_duration_s = 0.3;
  v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_DOUBLE_EQ(v.msg.opening_duration_s, 0.3);
  for (const double bad : {-0.001, kMaxOpeningDurationS + 0.001}) {
    c.opening_duration_s = bad;
    EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range) << bad;
  }
  c.opening_duration_s = kNaN;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.opening_duration_s = 0.0;

  c.valve_opening = 1.5;
  EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range);
  c.valve_opening = kNaN;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.mode = 9;
  EXPECT_EQ(validate_command(c).reason, RejectReason::unknown);
}

TEST(LcmValidation, ExciteCommand) {
  auto c = command(hsa::command_t::EXCITE);
  c.excite_at_rod = true;
  c.excite_kind = hsa::command_t::EXCITE_PRMS;
  c.excite_levels = 5;
  c.excite_amplitude_m = 1e-3;
  c.excite_switching_s = 0.3;
  c.excite_duration_s = 20.0;
  c.excite_seed = 3;
  c.excite_kp = 0.0;  // none given: the default
  auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.kind, CommandKind::excite);
  EXPECT_TRUE(v.msg.excite.at_rod);
  EXPECT_EQ(v.msg.excite.kind, control::ExcitationKind::prms);
  EXPECT_EQ(v.msg.excite.levels, 5);
  EXPECT_DOUBLE_EQ(v.msg.excite.amplitude_m, 1e-3);
  EXPECT_DOUBLE_EQ(v.msg.excite.switching_time_s, 0.3);
  EXPECT_DOUBLE_EQ(v.msg.excite.duration_s, 20.0);
  EXPECT_EQ(v.msg.excite.seed, 3u);
  EXPECT_DOUBLE_EQ(v.msg.excite.kp_per_m, kDefaultExcitationKpPerM);
  c.excite_kp = 150.0;
  EXPECT_DOUBLE_EQ(validate_command(c).msg.excite.kp_per_m, 150.0);

  c.excite_kind = hsa::command_t::EXCITE_PRBS;
  c.excite_levels = 0;  // not read for a PRBS
  v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.excite.kind, control::ExcitationKind::prbs);
  c.excite_kind = 7;
  EXPECT_EQ(validate_command(c).reason, RejectReason::unknown);
  c.excite_kind = hsa::command_t::EXCITE_PRMS;
  for (const int bad : {1, kMaxExcitationLevels + 1}) {
    c.excite_levels = static_cast<std::int16_t>(bad);
    EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range) << bad;
  }
  c.excite_levels = 5;
  const auto refused = [&](double hsa::command_t::*field, double bad) {
    auto m = c;
    m.*field = bad;
    return validate_command(m).reason;
  };
  EXPECT_EQ(refused(&hsa::command_t::excite_amplitude_m, 0.0), RejectReason::out_of_range);
  EXPECT_EQ(refused(&hsa::command_t::excite_switching_s, -0.1), RejectReason::out_of_range);
  EXPECT_EQ(refused(&hsa::command_t::excite_duration_s, 0.0), RejectReason::out_of_range);
  EXPECT_EQ(refused(&hsa::command_t::excite_duration_s, kMaxExcitationDurationS + 1.0), RejectReason::out_of_range);
  EXPECT_EQ(refused(&hsa::command_t::excite_kp, -1.0), RejectReason::out_of_range);
  for (auto field : {&hsa::command_t::excite_working_point_m, &hsa::command_t::excite_amplitude_m,
                     &hsa::command_t::excite_switching_s, &hsa::command_t::excite_duration_s,
                     &hsa::command_t::excite_kp}) {
    EXPECT_EQ(refused(field, kNaN), RejectReason::non_finite);
  }
}

TEST(LcmValidation, GainsCommand) {
  auto c = command(hsa::command_t::GAINS);
  c.kp = 85.0;
  c.ki = 0.0;  // P control is allowed
  const auto v = validate_command(c);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v.msg.kind, CommandKind::gains);
  EXPECT_DOUBLE_EQ(v.msg.gains.kp, 85.0);
  EXPECT_DOUBLE_EQ(v.msg.gains.ki, 0.0);

  c.kp = kNaN;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.kp = 85.0;
  c.ki = kInf;
  EXPECT_EQ(validate_command(c).reason, RejectReason::non_finite);
  c.ki = -1.0;
  EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range);
  c.ki = 460.0;
  c.kp = 0.0;
  EXPECT_EQ(validate_command(c).reason, RejectReason::out_of_range);
}

// --- decoding --------------------------------------------------------------------------------------

TEST(LcmValidation, DecodesExactlyTheBytesOfAMessage) {
  const auto bytes = encode(setpoint(0.2));
  hsa::setpoint_t s;
  ASSERT_TRUE(decode_exact(s, bytes.data(), bytes.size()));
  EXPECT_EQ(s.seq, 7);
  EXPECT_DOUBLE_EQ(s.position_m, 0.2);

  auto c = command(hsa::command_t::GAINS);
  c.ki = 20.0;
  const auto cmd = encode(c);
  hsa::command_t back;
  ASSERT_TRUE(decode_exact(back, cmd.data(), cmd.size()));
  EXPECT_DOUBLE_EQ(back.ki, 20.0);
}

TEST(LcmValidation, AStringLengthOfZeroOrBelowIsRefused) {
  hsa::setpoint_t signed_setpoint = setpoint(0.2);
  signed_setpoint.operator_id = "op";
  const auto bytes = encode(signed_setpoint);
  // The operator id's length field: "op" and its NUL, 3, as a big-endian int32 before the text.
  const std::vector<std::uint8_t> length_3 = {0, 0, 0, 3, 'o', 'p', 0};
  const auto at = std::search(bytes.begin(), bytes.end(), length_3.begin(), length_3.end());
  ASSERT_NE(at, bytes.end());
  // 0, -1 and INT32_MIN: lcm-gen 1.3.1 would assign SIZE_MAX (throws) or INT32_MAX (reads 2 GB
  // past the datagram) bytes; the build patches its decoders (msgs/CMakeLists.txt).
  const std::vector<std::vector<std::uint8_t>> forged_lengths = {{0, 0, 0, 0}, {0xff, 0xff, 0xff, 0xff}, {0x80, 0, 0, 0}};
  for (const auto& forged : forged_lengths) {
    auto bad = bytes;
    std::copy(forged.begin(), forged.end(), bad.begin() + (at - bytes.begin()));
    hsa::setpoint_t s;
    bool decoded = true;
    EXPECT_NO_THROW(decoded = decode_exact(s, bad.data(), bad.size()));
    EXPECT_FALSE(decoded);
  }
}

TEST(LcmValidation, RejectsBytesThatAreNotExactlyOneMessage) {
  const auto bytes = encode(setpoint(0.2));
  hsa::setpoint_t s;
  hsa::command_t c;
  // Truncated.
  EXPECT_FALSE(decode_exact(s, bytes.data(), bytes.size() - 1));
  // A valid message with junk after it.
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(decode_exact(s, longer.data(), longer.size()));
  // Another type on this channel: the fingerprint differs.
  const auto cmd = encode(command(hsa::command_t::ENABLE));
  EXPECT_FALSE(decode_exact(s, cmd.data(), cmd.size()));
  EXPECT_FALSE(decode_exact(c, bytes.data(), bytes.size()));
  // Garbage and nothing.
  const std::uint8_t junk[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
  EXPECT_FALSE(decode_exact(s, junk, sizeof junk));
  EXPECT_FALSE(decode_exact(c, nullptr, 0));
}

TEST(LcmValidation, ReasonNames) {
  EXPECT_EQ(to_string(RejectReason::non_finite), "non_finite");
  EXPECT_EQ(to_string(RejectReason::out_of_range), "out_of_range");
  EXPECT_EQ(to_string(RejectReason::decode), "decode");
  EXPECT_EQ(to_string(RejectReason::unknown), "unknown");
}

// --- URL -------------------------------------------------------------------------------------------

TEST(LcmUrl, AddsReceiveBufferToUdpmUrls) {
  EXPECT_EQ(lcm_url_with_recv_buf("udpm://239.255.76.67:7667", 4096), "udpm://239.255.76.67:7667?recv_buf_size=4096");
  EXPECT_EQ(lcm_url_with_recv_buf("udpm://239.255.76.67:7667?ttl=0", 4096),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4096");
  EXPECT_EQ(lcm_url_with_recv_buf("", 100), std::string(kFallbackLcmUrl) + "&recv_buf_size=100");
}

TEST(UdpmAddress, IsTheGroupAndPortWithoutTheOptions) {
  const UdpmAddress expected{"239.255.76.67", 7667};
  EXPECT_EQ(udpm_address("udpm://239.255.76.67:7667?ttl=0"), expected);
  EXPECT_EQ(udpm_address("udpm://239.255.76.67:7667?ttl=1&recv_buf_size=4096"), expected);
  EXPECT_EQ(udpm_address("udpm://239.255.76.67?ttl=0"), expected) << "LCM's default port";
  EXPECT_EQ(udpm_address(""), expected) << "the fallback URL";
  EXPECT_EQ(udpm_address("udpm://239.255.76.67:7700")->port, 7700);
  EXPECT_EQ(udpm_address("memq://"), std::nullopt);
  EXPECT_THROW((void)udpm_address("udpm://239.255.76.67:http?ttl=0"), std::invalid_argument);
  EXPECT_THROW((void)udpm_address("udpm://239.255.76.67:70000"), std::invalid_argument);
  EXPECT_THROW((void)udpm_address("udpm://lcm-group:7667"), std::invalid_argument);
}

TEST(LcmUrl, KeepsAnExplicitReceiveBufferAndOtherProviders) {
  EXPECT_EQ(lcm_url_with_recv_buf("udpm://239.255.76.67:7667?recv_buf_size=1&ttl=0", 4096),
            "udpm://239.255.76.67:7667?recv_buf_size=1&ttl=0");
  EXPECT_EQ(lcm_url_with_recv_buf("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=1", 4096),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=1");
  EXPECT_EQ(lcm_url_with_recv_buf("memq://", 4096), "memq://");
}

// --- seq gaps -------------------------------------------------------------------------

TEST(SeqGapCounter, CountsMissingMessagesAndResyncsOnRestart) {
  SeqGapCounter c;
  EXPECT_EQ(c.observe(100), 0u);  // first message: nothing known before it
  EXPECT_EQ(c.observe(101), 0u);
  EXPECT_EQ(c.observe(104), 2u);
  EXPECT_EQ(c.observe(104), 0u);  // duplicate
  EXPECT_EQ(c.observe(1), 0u);    // sender restarted
  EXPECT_EQ(c.observe(3), 1u);
  EXPECT_EQ(c.observe(3 + static_cast<std::int64_t>(SeqGapCounter::kMaxPlausibleGap) + 2), 0u);  // renumbered
}

// Two senders on one channel, each numbering from its own start: interleaved, no gap is counted;
// one skipping three messages counts three.
TEST(SenderSeqGaps, CountsEachSendersGapsAndNotTheInterleaving) {
  SenderSeqGaps g;
  std::uint64_t gaps = 0;
  for (std::int64_t k = 0; k < 10; ++k) {
    gaps += g.observe("alice", 5 + k);
    gaps += g.observe("bob", 1000 + k);
  }
  EXPECT_EQ(gaps, 0u);
  EXPECT_EQ(g.observe("alice", 15 + 3), 3u);  // alice's 15, 16, 17 never arrived
  EXPECT_EQ(g.observe("bob", 1010), 0u);
}

TEST(SenderSeqGaps, ForgetsTheLeastRecentlyHeardSenderBeyondItsBound) {
  SenderSeqGaps g;
  (void)g.observe("first", 1);
  for (std::size_t i = 0; i < SenderSeqGaps::kMaxSenders; ++i) (void)g.observe("other" + std::to_string(i), 1);
  // "first" was forgotten to make room: its next message starts it afresh, so no gap is counted.
  EXPECT_EQ(g.observe("first", 50), 0u);
  EXPECT_EQ(g.observe("first", 52), 1u);
}

// Without an operator id there is nothing to tell unsigned senders apart: they are one sender.
TEST(SenderSeqGaps, UnsignedSendersShareOneCount) {
  SenderSeqGaps g;
  EXPECT_EQ(g.observe("", 1), 0u);
  EXPECT_EQ(g.observe("alice", 100), 0u);
  EXPECT_EQ(g.observe("", 4), 2u);  // the unsigned numbering 1 → 4, not disturbed by alice
}

// --- conversion ------------------------------------------------------------------------------------

TEST(LcmConversion, TelemetryFields) {
  TelemetrySample s;
  s.utime = 42;
  s.tick = 12345;
  s.position_m = 0.1;
  s.pressure_b_pa = 5e6;
  s.current_ref_a = -0.02;
  s.state = AxisState::enabled;
  s.holding = true;
  s.lateness_max_ns = 7000;
  s.overruns = 3;
  s.setpoint_utime = 1'700'000'123;
  s.valve_enabled = true;
  const hsa::telemetry_t t = to_lcm(s);
  EXPECT_EQ(t.utime, 42);
  EXPECT_EQ(t.seq, 12345);
  EXPECT_DOUBLE_EQ(t.position_m, 0.1);
  EXPECT_DOUBLE_EQ(t.pressure_b_pa, 5e6);
  EXPECT_DOUBLE_EQ(t.current_ref_a, -0.02);
  EXPECT_EQ(t.state, int{hsa::status_t::STATE_ENABLED});
  EXPECT_TRUE(t.holding);
  EXPECT_EQ(t.lateness_max_ns, 7000);
  EXPECT_EQ(t.overruns, 3);
  EXPECT_EQ(t.setpoint_utime, 1'700'000'123);  // the stamp of the setpoint in effect, unchanged
  EXPECT_TRUE(t.valve_enabled);
}

// Each input's age goes out in µs with its stale bit; an input the axis does not have stays −1.
TEST(LcmConversion, TelemetryCarriesEachInputsAgeAndStaleMark) {
  TelemetrySample s;
  const auto at = [&](FaultSignal which) -> InputAge& { return s.inputs[static_cast<std::size_t>(which) - 1]; };
  at(FaultSignal::position) = {2'345'678'999, true};
  at(FaultSignal::pressure_a) = {1'500, false};
  at(FaultSignal::pressure_b) = {0, false};
  at(FaultSignal::spool) = {};  // no spool
  at(FaultSignal::estop) = {250'000'000, true};
  s.estop = true;
  const hsa::telemetry_t t = to_lcm(s);
  EXPECT_EQ(t.position_age_us, 2'345'678);
  EXPECT_EQ(t.pressure_a_age_us, 1);
  EXPECT_EQ(t.pressure_b_age_us, 0);
  EXPECT_EQ(t.spool_age_us, -1);
  EXPECT_EQ(t.estop_age_us, 250'000);
  EXPECT_TRUE(t.estop);
  EXPECT_EQ(t.stale, hsa::telemetry_t::STALE_POSITION | hsa::telemetry_t::STALE_ESTOP);
}

TEST(LcmConversion, StatusCarriesTheFlightRecordersCountsAndCondition) {
  StatusSample s;
  s.captures_written = 3;
  s.capture_triggers_merged = 4;
  s.capture_triggers_dropped = 5;
  s.capture_write_failures = 6;
  std::strcpy(s.capture_condition, "following_error_m above 0.001 (single, 1.5 s before, 0.5 s after)");
  hsa::status_t m = to_lcm(s, AxisCounters{}, 1);
  EXPECT_EQ(m.captures_written, 3);
  EXPECT_EQ(m.capture_triggers_merged, 4);
  EXPECT_EQ(m.capture_triggers_dropped, 5);
  EXPECT_EQ(m.capture_write_failures, 6);
  EXPECT_EQ(m.capture_condition, "following_error_m above 0.001 (single, 1.5 s before, 0.5 s after)");
  std::memset(s.capture_condition, 'y', sizeof s.capture_condition);  // no NUL: must not overrun
  m = to_lcm(s, AxisCounters{}, 1);
  EXPECT_EQ(m.capture_condition, std::string(sizeof s.capture_condition, 'y'));
}

TEST(LcmConversion, StatusFaultsCountersAndGrant) {
  StatusSample s;
  s.state = AxisState::fault;
  s.mode = ControlMode::open_loop;
  s.fault = FaultReason::over_pressure;
  std::memset(s.fault_text, 'x', sizeof s.fault_text);  // no NUL: must not overrun
  s.rt_minor_faults = 4;
  s.sched_fifo = true;
  s.rt_priority = 80;
  s.rt_cpu = 3;
  s.num_drivers = 1;
  std::strcpy(s.drivers[0].name, "io");
  std::strcpy(s.drivers[0].plugin, "modbus");
  std::strcpy(s.drivers[0].state, "active");
  s.drivers[0].link = DriverEntry::Link::down;
  std::strcpy(s.drivers[0].last_error, "Modbus TCP 127.0.0.1:1502: Connection refused");
  s.drivers[0].num_counters = 2;
  std::strcpy(s.drivers[0].counter_name[0], "link_errors");
  s.drivers[0].counter_value[0] = 3;
  std::strcpy(s.drivers[0].counter_name[1], "transaction_errors");
  s.num_results = 2;
  std::strcpy(s.results[0].from.operator_id, "alice");
  s.results[0].from.counter = 17;
  std::strcpy(s.results[0].reason, "axis not ENABLED: enable it first");
  std::strcpy(s.results[1].from.operator_id, "bob");
  s.results[1].from.counter = 3;
  s.results[1].accepted = true;
  AxisCounters c;
  c.rejected[static_cast<std::size_t>(RejectReason::non_finite)] = 5;
  c.rejected[static_cast<std::size_t>(RejectReason::out_of_range)] = 6;
  c.lcm_seq_gaps = 7;
  c.telemetry_ring_drops = 8;
  c.rejected[static_cast<std::size_t>(RejectReason::unknown_operator)] = 9;
  c.rejected[static_cast<std::size_t>(RejectReason::bad_mac)] = 10;
  c.rejected[static_cast<std::size_t>(RejectReason::replay)] = 11;
  c.rejected[static_cast<std::size_t>(RejectReason::stale_stamp)] = 12;

  const hsa::status_t m = to_lcm(s, c, 999);
  EXPECT_EQ(m.utime, 999);
  EXPECT_EQ(m.state, int{hsa::status_t::STATE_FAULT});
  EXPECT_EQ(m.mode, int{hsa::command_t::MODE_VALVE_OPENING});
  ASSERT_EQ(m.num_faults, 1);
  ASSERT_EQ(m.fault_code.size(), 1u);
  ASSERT_EQ(m.fault_reason.size(), 1u);
  EXPECT_EQ(m.fault_code[0], int{hsa::status_t::FAULT_PRESSURE});
  EXPECT_EQ(m.fault_reason[0].size(), sizeof s.fault_text);
  EXPECT_EQ(m.rejected_non_finite, 5);
  EXPECT_EQ(m.rejected_out_of_range, 6);
  EXPECT_EQ(m.lcm_seq_gaps, 7);
  EXPECT_EQ(m.telemetry_ring_drops, 8);
  EXPECT_EQ(m.rejected_unknown_operator, 9);
  EXPECT_EQ(m.rejected_bad_mac, 10);
  EXPECT_EQ(m.rejected_replay, 11);
  EXPECT_EQ(m.rejected_stamp, 12);
  EXPECT_EQ(m.rt_minor_faults, 4);
  EXPECT_TRUE(m.sched_fifo);
  EXPECT_FALSE(m.memory_locked);
  EXPECT_EQ(m.rt_priority, 80);
  EXPECT_EQ(m.rt_cpu, 3);
  ASSERT_EQ(m.num_drivers, 1);
  const hsa::driver_status_t& d = m.drivers[0];
  EXPECT_EQ(d.name, "io");
  EXPECT_EQ(d.plugin, "modbus");
  EXPECT_EQ(d.state, "active");
  EXPECT_EQ(d.link, int{hsa::driver_status_t::LINK_DOWN});
  EXPECT_EQ(d.last_error, "Modbus TCP 127.0.0.1:1502: Connection refused");
  ASSERT_EQ(d.num_counters, 2);
  EXPECT_EQ(d.counter_name[0], "link_errors");
  EXPECT_EQ(d.counter_value[0], 3);
  EXPECT_EQ(d.counter_value[1], 0);
  ASSERT_EQ(m.num_results, 2);
  EXPECT_EQ(m.result_operator, (std::vector<std::string>{"alice", "bob"}));
  EXPECT_EQ(m.result_counter, (std::vector<std::int64_t>{17, 3}));
  EXPECT_EQ(m.result_accepted, (std::vector<std::int8_t>{0, 1}));
  EXPECT_EQ(m.result_reason, (std::vector<std::string>{"axis not ENABLED: enable it first", ""}));
  // And it encodes: the array lengths agree with num_faults and num_drivers.
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_GT(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
}

TEST(LcmConversion, StatusChangeIsStateModeHoldFaultOrANewAnswer) {
  StatusSample a;
  StatusSample b = a;
  b.utime = 1000;
  b.rt_overruns = 5;  // counters are not a change
  EXPECT_FALSE(status_changed(a, b));
  b.state = AxisState::enabled;
  EXPECT_TRUE(status_changed(a, b));
  b = a;
  b.holding = true;
  EXPECT_TRUE(status_changed(a, b));
  b = a;
  b.mode = ControlMode::open_loop;
  EXPECT_TRUE(status_changed(a, b));
  b = a;
  b.fault = FaultReason::over_pressure;
  EXPECT_TRUE(status_changed(a, b));
  a.fault = FaultReason::over_pressure;
  EXPECT_FALSE(status_changed(a, b));
  std::strcpy(b.fault_text, "new wording");  // same fault, new text: not a change
  EXPECT_FALSE(status_changed(a, b));
  b.fault = FaultReason::driver_error;
  EXPECT_TRUE(status_changed(a, b));
  // A new answer to a command is a change: its sender is waiting for it.
  b = a;
  b.num_results = 1;
  b.results[0].from.counter = 4;
  EXPECT_TRUE(status_changed(a, b));
  a = b;
  b.results[0].from.counter = 5;
  EXPECT_TRUE(status_changed(a, b));
}

// --- configuration (refused before LCM is opened: no socket in this test) ---------------------------

LcmBridgeConfig good_config() {
  LcmBridgeConfig c;
  c.axes = {{"x", kLimits}};
  return c;
}

TEST(LcmBridgeConfig, RefusesBadConfigurations) {
  auto c = good_config();
  c.axes.clear();
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);

  c = good_config();
  c.axes.push_back({"x", kLimits});
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);  // duplicate

  for (const char* name : {"", "a.b", "a/b", "a b", "x*"}) {
    c = good_config();
    c.axes[0].name = name;
    EXPECT_THROW(LcmBridge{c}, std::invalid_argument) << "name '" << name << "'";
  }

  c = good_config();
  c.axes[0].limits = AxisLimits{0.3, 0.0};
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);

  c = good_config();
  c.status_rate_hz = 0.0;
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);

  c = good_config();
  c.rings.setpoints = 1000;  // not a power of two
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);

  c = good_config();
  c.poll_interval = std::chrono::milliseconds(0);
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);

  c = good_config();
  c.subscription_queue_capacity = 0;
  EXPECT_THROW(LcmBridge{c}, std::invalid_argument);
}

TEST(LcmBridgeConfig, ChannelNames) {
  EXPECT_EQ(setpoint_channel("x"), "HSA/x/SETPOINT");
  EXPECT_EQ(command_channel("x"), "HSA/x/COMMAND");
  EXPECT_EQ(telemetry_channel("left_2"), "HSA/left_2/TELEMETRY");
  EXPECT_EQ(status_channel("y"), "HSA/y/STATUS");
}

}  // namespace
}  // namespace hsa::daemon
