#include "tools/hsactl/lcm_session.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "msgs/auth/message_mac.hpp"
#include "msgs/decode_exact.hpp"

namespace hsa::ctl {

namespace {

std::int64_t wall_clock_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

LcmSession::LcmSession(const std::string& url, const std::string& axis, std::optional<msgs::OperatorKey> key,
                       double window_s)
    : lcm_(url), axis_(axis), status_channel_("HSA/" + axis + "/STATUS"), verifier_(std::move(key), window_s) {
  if (!lcm_.good()) throw std::runtime_error("hsactl: cannot open LCM at '" + url + "'");
  // Untyped subscriptions, decoded with msgs::decode_exact: LCM's typed ones decode with lcm-gen's
  // code, which throws on a forged string length, and anyone can publish on these channels.
  lcm_.subscribeFunction(
      "HSA/" + axis + "/TELEMETRY",
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmSession* self) {
        hsa::telemetry_t msg;
        if (!msgs::decode_exact(msg, rbuf->data, rbuf->data_size)) return;
        self->telemetry_ = msg;
        ++self->telemetry_count_;
        if (self->on_telemetry) self->on_telemetry(msg);
      },
      this);
  lcm_.subscribeFunction(
      status_channel_,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, LcmSession* self) {
        hsa::status_t msg;
        if (msgs::decode_exact(msg, rbuf->data, rbuf->data_size)) self->on_status(msg);
      },
      this);
  // Any axis's status: the name is the channel's middle part, HSA/<axis>/STATUS. The number of
  // names kept is bounded, as anyone on the LAN may publish on made-up channels; an authentic
  // status is never replaced by one that is not.
  lcm_.subscribeFunction(
      "HSA/[^/]+/STATUS",
      +[](const lcm::ReceiveBuffer* rbuf, const std::string& channel, LcmSession* self) {
        hsa::status_t msg;
        if (!msgs::decode_exact(msg, rbuf->data, rbuf->data_size)) return;
        const std::string name = channel.substr(4, channel.size() - 4 - 7);
        if (self->axes_heard_.size() >= 256 && !self->axes_heard_.contains(name)) return;
        const bool authentic = self->verifier_.authentic(msg, channel, wall_clock_us());
        AxisHeard& heard = self->axes_heard_[name];
        if (authentic || !heard.authentic) heard = {msg.state, authentic};
      },
      this);
}

void LcmSession::on_status(const hsa::status_t& msg) {
  // With a key, only what it verifies; without one, nothing can be told apart: the last received.
  if (verifier_.can_verify() && !verifier_.judge(msg, status_channel_, wall_clock_us())) return;
  status_ = msg;
  ++status_count_;
}

std::int64_t LcmSession::now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

template <typename Message>
std::int64_t LcmSession::publish(const std::string& channel, Message& msg) {
  const auto wall = std::chrono::system_clock::now().time_since_epoch();
  msg.stamp_us = std::chrono::duration_cast<std::chrono::microseconds>(wall).count();
  // For the daemon whose status this session verified, and for no other: instance 0 (unbound)
  // until then, which only a daemon with require_auth = false obeys.
  if (const auto& daemon = verifier_.daemon()) {
    msg.system = daemon->system;
    msg.instance = daemon->instance;
  }
  const std::optional<msgs::OperatorKey>& key = verifier_.key();
  if (!key) {
    // Unsigned (for a daemon with require_auth = false): the counter still tells the acks apart.
    msg.counter = ++counter_;
    lcm_.publish(channel, &msg);
    return msg.counter;
  }
  // The daemon refuses a counter that is not above the last one it accepted from this operator
  // on this channel, across hsactl runs: the wall clock in ns keeps it rising from run to run.
  const std::int64_t wall_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wall).count();
  counter_ = std::max(counter_ + 1, wall_ns);
  msg.operator_id = key->operator_id;
  msg.counter = counter_;
  const std::vector<std::uint8_t> bytes = msgs::encode_signed(msg, key->key, channel);
  lcm_.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
  return counter_;
}

std::optional<std::int64_t> LcmSession::acknowledged(const hsa::status_t& status) const {
  const std::string me = operator_id();
  for (int i = 0; i < status.num_acks; ++i) {
    if (status.ack_operator[i] == me) return status.ack_counter[i];
  }
  return std::nullopt;
}

std::optional<std::size_t> LcmSession::answer_to(const hsa::status_t& status, std::int64_t counter) const {
  const std::string me = operator_id();
  const auto n = static_cast<std::size_t>(std::max<int>(status.num_results, 0));
  for (std::size_t i = 0; i < n && i < status.result_counter.size() && i < status.result_operator.size(); ++i) {
    if (status.result_operator[i] == me && status.result_counter[i] == counter) return i;
  }
  return std::nullopt;
}

std::int64_t LcmSession::send_setpoint(double position_m) {
  hsa::setpoint_t msg{};
  msg.utime = now_us();
  msg.seq = ++setpoint_seq_;
  msg.position_m = position_m;
  msg.has_velocity_ff = false;
  return publish("HSA/" + axis_ + "/SETPOINT", msg);
}

hsa::command_t LcmSession::new_command(std::int8_t command) {
  hsa::command_t msg{};
  msg.utime = now_us();
  msg.seq = ++command_seq_;
  msg.command = command;
  return msg;
}

std::int64_t LcmSession::send(std::int8_t command, const std::function<void(hsa::command_t&)>& fill) {
  hsa::command_t msg = new_command(command);
  fill(msg);
  return publish("HSA/" + axis_ + "/COMMAND", msg);
}

std::int64_t LcmSession::send_command(std::int8_t command, std::int8_t mode, double valve_opening, bool force) {
  return send(command, [&](hsa::command_t& msg) {
    msg.mode = mode;
    msg.valve_opening = valve_opening;
    msg.force = force;
  });
}

std::int64_t LcmSession::send_gains(double kp, double ki) {
  return send(hsa::command_t::GAINS, [&](hsa::command_t& msg) {
    msg.kp = kp;
    msg.ki = ki;
  });
}

std::int64_t LcmSession::send_move_to(double target_m, double speed_m_s, double accel_m_s2) {
  return send(hsa::command_t::MOVE_TO, [&](hsa::command_t& msg) {
    msg.target_m = target_m;
    msg.speed_m_s = speed_m_s;
    msg.accel_m_s2 = accel_m_s2;
  });
}

void LcmSession::poll(std::chrono::milliseconds slice) {
  // Handles what is already queued, then waits for more until the slice is over (a zero slice
  // only drains the queue).
  const auto deadline = std::chrono::steady_clock::now() + slice;
  for (int handled = 0; handled < 10000; ++handled) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (lcm_.handleTimeout(static_cast<int>(std::max<long>(left.count(), 0))) <= 0 && left.count() <= 0) return;
  }
}

bool LcmSession::run_until(std::chrono::steady_clock::duration timeout, const std::function<bool()>& until) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!until()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    lcm_.handleTimeout(static_cast<int>(std::min<long>(left.count(), 50)));
  }
  return true;
}

const char* state_name(std::int8_t state) {
  switch (state) {
    case hsa::status_t::STATE_INIT: return "INIT";
    case hsa::status_t::STATE_DISABLED: return "DISABLED";
    case hsa::status_t::STATE_ENABLED: return "ENABLED";
    case hsa::status_t::STATE_FAULT: return "FAULT";
    case hsa::status_t::STATE_ESTOP: return "ESTOP";
  }
  return "UNKNOWN";
}

const char* mode_name(std::int8_t mode) {
  return mode == hsa::command_t::MODE_VALVE_OPENING ? "open-loop" : "position";
}

}  // namespace hsa::ctl
