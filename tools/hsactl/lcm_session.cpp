#include "tools/hsactl/lcm_session.hpp"

#include <algorithm>
#include <stdexcept>

namespace hsa::ctl {

LcmSession::LcmSession(const std::string& url, const std::string& axis) : lcm_(url), axis_(axis) {
  if (!lcm_.good()) throw std::runtime_error("hsactl: cannot open LCM at '" + url + "'");
  lcm_.subscribeFunction(
      "HSA/" + axis + "/TELEMETRY",
      +[](const lcm::ReceiveBuffer*, const std::string&, const hsa::telemetry_t* msg, LcmSession* self) {
        self->telemetry_ = *msg;
        ++self->telemetry_count_;
        if (self->on_telemetry) self->on_telemetry(*msg);
      },
      this);
  lcm_.subscribeFunction(
      "HSA/" + axis + "/STATUS",
      +[](const lcm::ReceiveBuffer*, const std::string&, const hsa::status_t* msg, LcmSession* self) {
        self->status_ = *msg;
        ++self->status_count_;
      },
      this);
}

std::int64_t LcmSession::now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void LcmSession::send_setpoint(double position_m) {
  hsa::setpoint_t msg{};
  msg.utime = now_us();
  msg.seq = ++setpoint_seq_;
  msg.position_m = position_m;
  msg.has_velocity_ff = false;
  lcm_.publish("HSA/" + axis_ + "/SETPOINT", &msg);
}

void LcmSession::send_command(std::int8_t command, std::int8_t mode, double valve_opening) {
  hsa::command_t msg{};
  msg.utime = now_us();
  msg.seq = ++command_seq_;
  msg.command = command;
  msg.mode = mode;
  msg.valve_opening = valve_opening;
  lcm_.publish("HSA/" + axis_ + "/COMMAND", &msg);
}

void LcmSession::send_gains(double kp, double ki) {
  hsa::command_t msg{};
  msg.utime = now_us();
  msg.seq = ++command_seq_;
  msg.command = hsa::command_t::GAINS;
  msg.kp = kp;
  msg.ki = ki;
  lcm_.publish("HSA/" + axis_ + "/COMMAND", &msg);
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

}  // namespace hsa::ctl
