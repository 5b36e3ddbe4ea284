// hsactl's side of LCM: typed publishing to one axis's channels and bounded waits for its
// telemetry and status. Every wait has a deadline, so hsactl never hangs on a silent daemon.
//
// The status it keeps is the last one it believed (status_verifier.hpp): signed by hsad for this
// operator, from the daemon it first verified, fresh. What it did not believe is counted and can
// be named. Setpoints and commands are signed for that daemon (its system and instance), so no
// other hsad obeys them. Without a key nothing can be verified: the status kept is then the last
// one received, and can_verify() says it is unverified. Telemetry is never verified.
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
#include "tools/hsactl/status_verifier.hpp"

namespace hsa::ctl {

class LcmSession {
 public:
  // `key` signs every setpoint and command and verifies every status (msgs/auth/). Without one,
  // messages go unsigned (only a daemon with require_auth = false obeys them) and no status can be
  // verified. A status is believed within ±window_s of this host's wall clock.
  LcmSession(const std::string& url, const std::string& axis, std::optional<msgs::OperatorKey> key,
             double window_s = 2.0);

  [[nodiscard]] bool signing() const { return verifier_.can_verify(); }
  [[nodiscard]] bool can_verify() const { return verifier_.can_verify(); }
  [[nodiscard]] std::string operator_id() const { return signing() ? verifier_.key()->operator_id : std::string(); }
  [[nodiscard]] const StatusVerifier& verifier() const { return verifier_; }
  // What hsactl says after each answer it shows without a key: "" when it can verify.
  [[nodiscard]] const char* unverified_tag() const {
    return can_verify() ? "" : " [UNVERIFIED: no key (--key, HSA_KEY) to authenticate hsad's answer]";
  }

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
  // The last status believed (with a key: verified; without: the last received).
  [[nodiscard]] const std::optional<hsa::status_t>& status() const { return status_; }
  // Every axis whose status was heard on this LCM URL, by name, with its latest state
  // (status_t.STATE_*) and whether that status was authentic (MAC and stamp): for `hsactl axes`,
  // and to say which axes do answer when this one does not.
  struct AxisHeard {
    std::int8_t state = 0;
    bool authentic = false;
  };
  [[nodiscard]] const std::map<std::string, AxisHeard>& axes_heard() const { return axes_heard_; }
  [[nodiscard]] std::uint64_t telemetry_count() const { return telemetry_count_; }
  // Statuses believed (received, without a key).
  [[nodiscard]] std::uint64_t status_count() const { return status_count_; }

  std::function<void(const hsa::telemetry_t&)> on_telemetry;  // optional tap (record, watch)

  [[nodiscard]] static std::int64_t now_us();
  [[nodiscard]] const std::string& axis() const { return axis_; }

 private:
  // A command message with its stamp and this session's next seq; the caller fills the rest.
  hsa::command_t new_command(std::int8_t command);
  template <typename Message>
  std::int64_t publish(const std::string& channel, Message& msg);

  void on_status(const hsa::status_t& msg);

  lcm::LCM lcm_;
  std::string axis_;
  std::string status_channel_;
  StatusVerifier verifier_;
  std::int64_t counter_ = 0;
  std::int64_t setpoint_seq_ = 0;
  std::int64_t command_seq_ = 0;
  std::optional<hsa::telemetry_t> telemetry_;
  std::optional<hsa::status_t> status_;
  std::map<std::string, AxisHeard> axes_heard_;
  std::uint64_t telemetry_count_ = 0;
  std::uint64_t status_count_ = 0;
};

// The axis state and control mode names used on screen and in JSON.
[[nodiscard]] const char* state_name(std::int8_t state);
[[nodiscard]] const char* mode_name(std::int8_t mode);

}  // namespace hsa::ctl
