// The LCM side of hsad: one normal (non-RT) thread that owns the lcm::LCM instance.
//
// For each configured axis it subscribes HSA/<axis>/SETPOINT and HSA/<axis>/COMMAND, decodes,
// authenticates (message_authenticator.hpp), validates (message_validation.hpp) and checks against
// the axis's lease (command_lease.hpp) every message and queues the valid ones, as plain structs,
// into the axis's port (daemon/axis/axis_port.hpp) in the supervisor's own types: setpoints for the
// RT thread, commands with their sender for the operator thread. Rejected messages have no effect
// and are counted by reason. In the other direction it drains the telemetry ring the RT thread
// fills and the status ring the operator thread fills, and
// publishes every telemetry sample on HSA/<axis>/TELEMETRY (the RT thread pushes one per window
// of the axis's telemetry_rate_hz, daemon/axis/tick_decimator.hpp), and HSA/<axis>/STATUS at
// `status_rate_hz` and at once on every change (message_conversion.hpp). Each status carries this
// daemon's system name and instance and is signed for every operator key it holds
// (msgs/auth/status_mac.hpp), so that an operator believes only hsad; telemetry is not signed.
// The RT thread never calls LCM: LCM's publish allocates and makes system calls.
//
// LCM drops silently in two places at 10 kHz: the per-subscription queue (30 messages by default)
// and the socket receive buffer (the kernel default). The bridge sets both deliberately
// (`subscription_queue_capacity`, `recv_buf_size` added to the URL, lcm_url.hpp) and counts what
// is lost anyway from gaps in each sender's seq (sender_seq_gaps.hpp).
//
// Commands cannot be starved by setpoints. They arrive on an LCM instance of their own (its own
// socket, receive thread and queue, subscribed to the COMMAND channels only), and the thread
// drains that one first; then every pending setpoint, in batches between which it drains the
// commands again. A flood of setpoints therefore delays a DISABLE by at most one batch. Each
// wake-up handles what is pending up to a bound (a few hundred messages), then sends the status
// and telemetry that confirm commands to their senders, and goes on. A command taken is
// acknowledged by its operator and counter in the next status, which goes out in the same wake-up.
//
// The thread waits on both instances' descriptors for at most `poll_interval`, so telemetry
// leaves within about that long and stop() returns within about that long.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "daemon/axis/axis_port.hpp"
#include "daemon/lcm_bridge/command_lease.hpp"
#include "daemon/lcm_bridge/lcm_socket_guard.hpp"
#include "daemon/lcm_bridge/lcm_url.hpp"
#include "daemon/lcm_bridge/message_authenticator.hpp"
#include "daemon/lcm_bridge/message_validation.hpp"

namespace lcm {
class LCM;
}

namespace hsa::daemon {

// What every status says while authentication is off.
inline constexpr const char* kAuthOffWarning =
    "authentication is off (require_auth = false): anyone who reaches the LCM URL can command this axis";

struct AxisEndpoint {
  std::string name;    // [A-Za-z0-9_-]+: it becomes part of the channel names (LCM reads them as regexes)
  AxisLimits limits;   // what a setpoint may ask for
};

struct LcmBridgeConfig {
  std::vector<AxisEndpoint> axes;
  std::string lcm_url{kFallbackLcmUrl};
  std::size_t recv_buf_size = kDefaultRecvBufSize;  // added to a udpm URL that does not set it
  // Per subscription; 1000 is 100 ms of setpoints at 10 kHz (LCM's default, 30, is 3 ms).
  int subscription_queue_capacity = 1000;
  double status_rate_hz = 10.0;
  std::chrono::milliseconds poll_interval{1};
  RingCapacities rings;
  AuthConfig auth;  // who may command the axes; required by default, so it needs keys
  double lease_timeout_s = 30.0;  // an axis's lease ends this long after its holder's last message
};

// Channel names of an axis.
[[nodiscard]] std::string setpoint_channel(std::string_view axis);
[[nodiscard]] std::string command_channel(std::string_view axis);
[[nodiscard]] std::string telemetry_channel(std::string_view axis);
[[nodiscard]] std::string status_channel(std::string_view axis);

class LcmBridge {
 public:
  // Operators an axis remembers acknowledgements for (the least recently heard is forgotten).
  static constexpr std::size_t kMaxAcks = 16;

  // Allocates every ring and opens LCM (subscriptions included), so nothing of this is left to do
  // once the RT thread runs. Throws std::invalid_argument for a bad configuration (no axes, bad or
  // duplicate axis name, invalid limits, rates that do not divide, ring sizes not powers of two)
  // or authentication required without keys) and std::runtime_error when LCM cannot be opened.
  explicit LcmBridge(LcmBridgeConfig config);
  ~LcmBridge();  // stop()

  LcmBridge(const LcmBridge&) = delete;
  LcmBridge& operator=(const LcmBridge&) = delete;

  // Starts / stops the LCM thread. start() after stop() starts it again; both are idempotent.
  // Call them from one (non-RT) thread.
  void start();
  void stop();

  // The axes in configuration order; their addresses are stable for the bridge's lifetime.
  [[nodiscard]] std::size_t axis_count() const { return axes_.size(); }
  [[nodiscard]] bool auth_required() const { return auth_.required(); }
  // What every status and every command for this daemon names: [auth] system_name, and this start's instance.
  [[nodiscard]] const std::string& system() const { return auth_.system(); }
  [[nodiscard]] std::int64_t instance() const { return auth_.instance(); }

  // Throws std::out_of_range for an index >= axis_count().
  [[nodiscard]] AxisPort& axis(std::size_t index);
  [[nodiscard]] const AxisPort& axis(std::size_t index) const;
  // nullptr when there is no such axis.
  [[nodiscard]] AxisPort* find_axis(std::string_view name);

  // The URL LCM was opened with (recv_buf_size included).
  [[nodiscard]] const std::string& lcm_url() const { return url_; }

 private:
  struct Axis;

  void run();
  // Handles what is pending, commands first (bounded): the number of messages handled, or -1 when
  // LCM failed.
  int drain();
  void on_setpoint(Axis& axis, const void* data, std::size_t size);
  void on_command(Axis& axis, const void* data, std::size_t size);
  void acknowledge(Axis& axis, const std::string& operator_id, std::int64_t counter);
  void service_outbound(std::chrono::steady_clock::time_point now);
  void publish_status(Axis& axis, std::chrono::steady_clock::time_point now);

  LcmBridgeConfig config_;
  MessageAuthenticator auth_;
  std::string url_;
  std::optional<LcmSocketGuard> socket_guard_;  // udpm: armed before, and for as long as, LCM's sockets
  std::unique_ptr<lcm::LCM> lcm_;           // setpoints in; telemetry and status out
  std::unique_ptr<lcm::LCM> commands_lcm_;  // commands in, on their own socket and queue
  std::vector<std::unique_ptr<Axis>> axes_;
  std::atomic<bool> stop_requested_{false};
  std::thread thread_;
};

}  // namespace hsa::daemon
