// hsactl's side of LCM: typed publishing to one axis's channels and bounded waits for its
// telemetry and status. Every wait has a deadline, so hsactl never hangs on a silent daemon.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "hsa/command_t.hpp"
#include "msgs/auth/operator_key.hpp"
#include "hsa/setpoint_t.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::ctl {

class LcmSession {
 public:
  LcmSession(const std::string& url, const std::string& axis);

  // Signs every setpoint and command from now on with this operator's key (msgs/auth/). Without a
  // key they go unsigned, which only a daemon with require_auth = false obeys.
  void set_key(msgs::OperatorKey key) { key_ = std::move(key); }
  [[nodiscard]] bool signing() const { return key_.has_value(); }
  [[nodiscard]] std::string operator_id() const { return key_ ? key_->operator_id : std::string(); }

  // Each send returns the message's counter, by which hsad acknowledges a command in its status.
  std::int64_t send_setpoint(double position_m);
  std::int64_t send_command(std::int8_t command, std::int8_t mode = 0, double valve_opening = 0.0, bool force = false);
  // A GAINS command: the cylinder PI's kp (1/m) and ki (1/(m s)).
  std::int64_t send_gains(double kp, double ki);
  std::int64_t send_move_to(double target_m, double speed_m_s, double accel_m_s2);
  // Any command: `fill` sets its payload on a message stamped and addressed as every command is
  // (the senders above are this with their fields), so a new command needs no sender of its own.
  std::int64_t send(std::int8_t command, const std::function<void(hsa::command_t&)>& fill);

  // The counter of this operator's last command that `status` acknowledges (nullopt: none).
  [[nodiscard]] std::optional<std::int64_t> acknowledged(const hsa::status_t& status) const;
  // Where `status` carries the axis's answer to this operator's command `counter` (an index into
  // its result_* arrays), or nullopt.
  [[nodiscard]] std::optional<std::size_t> answer_to(const hsa::status_t& status, std::int64_t counter) const;

  // Handles incoming messages until `until` returns true or the deadline passes; false on timeout.
  bool run_until(std::chrono::steady_clock::duration timeout, const std::function<bool()>& until);
  // Handles whatever arrives within `slice` (at most), then returns.
  void poll(std::chrono::milliseconds slice);

  [[nodiscard]] const std::optional<hsa::telemetry_t>& telemetry() const { return telemetry_; }
  [[nodiscard]] const std::optional<hsa::status_t>& status() const { return status_; }
  // Every axis whose status was heard on this LCM URL, by name, with its latest state
  // (status_t.STATE_*): for `hsactl axes`, and to say which axes do answer when this one does not.
  [[nodiscard]] const std::map<std::string, std::int8_t>& axes_heard() const { return axes_heard_; }
  [[nodiscard]] std::uint64_t telemetry_count() const { return telemetry_count_; }
  [[nodiscard]] std::uint64_t status_count() const { return status_count_; }

  std::function<void(const hsa::telemetry_t&)> on_telemetry;  // optional tap (record, watch)

  [[nodiscard]] static std::int64_t now_us();
  [[nodiscard]] const std::string& axis() const { return axis_; }

 private:
  // A command message with its stamp and this session's next seq; the caller fills the rest.
  hsa::command_t new_command(std::int8_t command);
  template <typename Message>
  std::int64_t publish(const std::string& channel, Message& msg);

  lcm::LCM lcm_;
  std::string axis_;
  std::optional<msgs::OperatorKey> key_;
  std::int64_t counter_ = 0;
  std::int64_t setpoint_seq_ = 0;
  std::int64_t command_seq_ = 0;
  std::optional<hsa::telemetry_t> telemetry_;
  std::optional<hsa::status_t> status_;
  std::map<std::string, std::int8_t> axes_heard_;
  std::uint64_t telemetry_count_ = 0;
  std::uint64_t status_count_ = 0;
};

// The axis state and control mode names used on screen and in JSON.
[[nodiscard]] const char* state_name(std::int8_t state);
[[nodiscard]] const char* mode_name(std::int8_t mode);

}  // namespace hsa::ctl
