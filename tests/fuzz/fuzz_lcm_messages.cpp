// What hsa does with every LCM datagram, on any bytes. The first input byte picks the type (by its
// value modulo 4: setpoint, command, status, telemetry); the rest is the message. hsad decodes
// setpoints and commands exactly (msgs/decode_exact.hpp), authenticates
// (daemon/lcm_bridge/message_authenticator.hpp) and validates them; hsactl and other clients
// decode status and telemetry. Invariants:
//   - bytes that decode are exactly one message: encoding it again gives the same bytes;
//   - authentication accepts only a message whose MAC the key makes;
//   - a message that validates carries only finite values within the axis's limits, and zeroes
//     the fields its kind does not use.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "daemon/lcm_bridge/message_authenticator.hpp"
#include "daemon/lcm_bridge/message_validation.hpp"
#include "hsa/status_t.hpp"
#include "msgs/auth/status_mac.hpp"
#include "hsa/telemetry_t.hpp"
#include "msgs/auth/message_mac.hpp"
#include "tests/fuzz/fuzz_target.hpp"

namespace {

using namespace hsa::daemon;

const std::string kSetpoints = "HSA/x/SETPOINT";
const std::string kCommands = "HSA/x/COMMAND";
const std::string kStatus = "HSA/x/STATUS";
constexpr AxisLimits kLimits{0.0, 0.3, 0.5};
constexpr std::int64_t kNow = 1'800'000'000'000'000;
const std::string kSystem = "rig";       // the daemon the seeds are signed for
constexpr std::int64_t kInstance = 42;

hsa::msgs::Key key() {
  hsa::msgs::Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<unsigned char>(i * 13 + 5);
  return k;
}

const MessageAuthenticator& authenticator() {
  static const MessageAuthenticator auth(AuthConfig{true, {{"op", key()}}, 2.0, kSystem, kInstance}, kNow - 60'000'000);
  return auth;
}

template <typename Message>
void round_trips(const Message& msg, const std::uint8_t* data, std::size_t size) {
  std::string again(static_cast<std::size_t>(msg.getEncodedSize()), '\0');
  HSA_FUZZ_CHECK(msg.encode(again.data(), 0, static_cast<int>(again.size())) == static_cast<int>(size));
  HSA_FUZZ_CHECK(std::memcmp(again.data(), data, size) == 0);
}

template <typename Message>
void authenticates_only_with_the_key(const Message& msg, const std::string& channel, const std::uint8_t* data,
                                     std::size_t size) {
  auto state = authenticator().channel(channel);
  const RejectReason r = authenticator().check(state, msg, data, size, kNow);
  if (r == RejectReason::none) {
    HSA_FUZZ_CHECK(msg.operator_id == "op");
    HSA_FUZZ_CHECK(hsa::msgs::mac_matches(key(), channel, data, size));
  }
}

void setpoint(const std::uint8_t* data, std::size_t size) {
  hsa::setpoint_t msg;
  if (!decode_exact(msg, data, size)) return;
  round_trips(msg, data, size);
  authenticates_only_with_the_key(msg, kSetpoints, data, size);
  const Validated<SetpointInput> v = validate_setpoint(msg, kLimits);
  if (!v.ok()) return;
  HSA_FUZZ_CHECK(std::isfinite(v.msg.target));
  HSA_FUZZ_CHECK(v.msg.target >= kLimits.min_position_m && v.msg.target <= kLimits.max_position_m);
  HSA_FUZZ_CHECK(std::isfinite(v.msg.velocity_m_s) && std::fabs(v.msg.velocity_m_s) <= kLimits.max_velocity_m_s);
  if (!msg.has_velocity_ff) HSA_FUZZ_CHECK(v.msg.velocity_m_s == 0.0);
}

void command(const std::uint8_t* data, std::size_t size) {
  hsa::command_t msg;
  if (!decode_exact(msg, data, size)) return;
  round_trips(msg, data, size);
  authenticates_only_with_the_key(msg, kCommands, data, size);
  const Validated<AxisCommand> v = validate_command(msg);
  if (!v.ok()) return;
  HSA_FUZZ_CHECK(std::isfinite(v.msg.opening) && std::fabs(v.msg.opening) <= 1.0);
  HSA_FUZZ_CHECK(std::isfinite(v.msg.gains.kp) && std::isfinite(v.msg.gains.ki) && v.msg.gains.ki >= 0.0);
  if (v.msg.kind == CommandKind::gains) {
    HSA_FUZZ_CHECK(v.msg.gains.kp > 0.0);
  } else {
    HSA_FUZZ_CHECK(v.msg.gains.kp == 0.0 && v.msg.gains.ki == 0.0);
  }
  if (v.msg.kind != CommandKind::set_mode) HSA_FUZZ_CHECK(v.msg.opening == 0.0 && !v.msg.has_opening);
  if (v.msg.kind != CommandKind::move_to) HSA_FUZZ_CHECK(v.msg.move.target_m == 0.0 && v.msg.move.speed_m_s == 0.0);
}

template <typename Message>
std::string encoded(const Message& msg) {
  std::string bytes(static_cast<std::size_t>(msg.getEncodedSize()), '\0');
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

template <typename Message>
std::string signed_seed(char selector, Message msg, const std::string& channel) {
  msg.system = kSystem;
  msg.instance = kInstance;
  msg.operator_id = "op";
  msg.counter = 1;
  msg.stamp_us = kNow;
  const std::vector<std::uint8_t> bytes = hsa::msgs::encode_signed(msg, key(), channel);
  return std::string(1, selector) + std::string(bytes.begin(), bytes.end());
}

// What a client does with what hsad publishes (and anyone else could).
template <typename Message>
void published(const std::uint8_t* data, std::size_t size) {
  Message msg;
  if (decode_exact(msg, data, size)) round_trips(msg, data, size);
}

// What hsactl does with a status: it believes one only if its MAC for the operator verifies, and
// then hsad, holding that key, would have signed exactly those bytes with exactly that MAC.
void status(const std::uint8_t* data, std::size_t size) {
  hsa::status_t msg;
  if (!decode_exact(msg, data, size)) return;
  round_trips(msg, data, size);
  const hsa::msgs::OperatorKey op{"op", key()};
  if (hsa::msgs::verify_status(msg, op, kStatus) != hsa::msgs::StatusMacCheck::verified) return;
  hsa::status_t again = msg;
  hsa::msgs::sign_status(again, {op}, kStatus);
  const auto mine = std::find(msg.mac_operator.begin(), msg.mac_operator.end(), "op") - msg.mac_operator.begin();
  HSA_FUZZ_CHECK(msg.mac.at(static_cast<std::size_t>(mine)) == again.mac.at(0));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  switch (data[0] % 4) {
    case 0: setpoint(data + 1, size - 1); break;
    case 1: command(data + 1, size - 1); break;
    case 2: status(data + 1, size - 1); break;
    case 3: published<hsa::telemetry_t>(data + 1, size - 1); break;
  }
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  std::vector<std::string> seeds;
  hsa::setpoint_t sp{};
  sp.position_m = 0.1;
  seeds.push_back(signed_seed('\0', sp, kSetpoints));
  sp.has_velocity_ff = true;
  sp.velocity_ff_m_s = 0.05;
  seeds.push_back(signed_seed('\0', sp, kSetpoints));
  for (const std::int8_t kind : {hsa::command_t::ENABLE, hsa::command_t::DISABLE, hsa::command_t::RESET,
                                 hsa::command_t::MODE, hsa::command_t::GAINS, hsa::command_t::ACQUIRE}) {
    hsa::command_t c{};
    c.command = kind;
    c.mode = hsa::command_t::MODE_VALVE_OPENING;
    c.valve_opening = 0.2;
    c.kp = 85.0;
    c.ki = 460.0;
    seeds.push_back(signed_seed('\1', c, kCommands));
  }
  hsa::status_t st{};
  st.num_faults = 1;
  st.fault_code = {hsa::status_t::FAULT_PRESSURE};
  st.fault_reason = {"pressure A 231 bar over limit 210 bar"};
  st.lease_holder = "op";
  st.num_acks = 1;
  st.ack_operator = {"op"};
  st.ack_counter = {7};
  st.system = kSystem;
  st.instance = kInstance;
  st.stamp_us = kNow;
  hsa::msgs::sign_status(st, {{"bob", key()}, {"op", key()}}, kStatus);
  hsa::telemetry_t te{};
  te.position_m = 0.12;
  for (const auto& [selector, bytes] : {std::pair{'\2', encoded(st)}, std::pair{'\3', encoded(te)}}) {
    seeds.push_back(std::string(1, selector) + bytes);
  }
  return seeds;
}
