#include "daemon/lcm_bridge/lcm_bridge.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <utility>

#include <lcm/lcm-cpp.hpp>

#include "daemon/lcm_bridge/message_conversion.hpp"
#include "daemon/lcm_bridge/sender_seq_gaps.hpp"
#include "msgs/auth/status_mac.hpp"

namespace hsa::daemon {

namespace {

using Clock = std::chrono::steady_clock;

std::string channel(std::string_view axis, std::string_view kind) {
  std::string out = "HSA/";
  out += axis;
  out += '/';
  out += kind;
  return out;
}

bool valid_axis_name(std::string_view name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

bool positive_finite(double x) { return std::isfinite(x) && x > 0.0; }

void check_config(const LcmBridgeConfig& c) {
  if (c.axes.empty()) throw std::invalid_argument("LcmBridge: no axes configured");
  std::set<std::string, std::less<>> names;
  for (const auto& axis : c.axes) {
    if (!valid_axis_name(axis.name)) {
      throw std::invalid_argument("LcmBridge: axis name '" + axis.name + "' must be [A-Za-z0-9_-]+");
    }
    if (!names.insert(axis.name).second) throw std::invalid_argument("LcmBridge: duplicate axis '" + axis.name + "'");
    if (!axis.limits.valid()) {
      throw std::invalid_argument("LcmBridge: axis '" + axis.name +
                                  "' needs finite min_position_m < max_position_m and max_velocity_m_s > 0");
    }
  }
  if (!positive_finite(c.status_rate_hz)) throw std::invalid_argument("LcmBridge: status_rate_hz must be positive");
  if (!positive_finite(c.lease_timeout_s)) throw std::invalid_argument("LcmBridge: lease_timeout_s must be positive");
  if (c.subscription_queue_capacity < 1) throw std::invalid_argument("LcmBridge: subscription_queue_capacity must be >= 1");
  if (c.recv_buf_size == 0) throw std::invalid_argument("LcmBridge: recv_buf_size must be positive");
  if (c.poll_interval < std::chrono::milliseconds(1) || c.poll_interval > std::chrono::seconds(1)) {
    throw std::invalid_argument("LcmBridge: poll_interval must be within [1 ms, 1 s]");
  }
}

std::int64_t utime_now() {
  // steady_clock is CLOCK_MONOTONIC on Linux: the clock the RT thread stamps its samples with.
  return std::chrono::duration_cast<std::chrono::microseconds>(Clock::now().time_since_epoch()).count();
}

}  // namespace

std::string setpoint_channel(std::string_view axis) { return channel(axis, "SETPOINT"); }
std::string command_channel(std::string_view axis) { return channel(axis, "COMMAND"); }
std::string telemetry_channel(std::string_view axis) { return channel(axis, "TELEMETRY"); }
std::string status_channel(std::string_view axis) { return channel(axis, "STATUS"); }

// Everything the LCM thread keeps per axis, next to the port the RT thread sees.
struct LcmBridge::Axis {
  Axis(LcmBridge& bridge, const AxisEndpoint& endpoint, const RingCapacities& rings,
       const MessageAuthenticator& auth, Clock::duration lease_timeout)
      : owner(&bridge),
        port(endpoint.name, endpoint.limits, rings),
        setpoint_auth(auth.channel(setpoint_channel(endpoint.name))),
        command_auth(auth.channel(command_channel(endpoint.name))),
        lease(lease_timeout),
        telemetry_channel_name(telemetry_channel(endpoint.name)),
        status_channel_name(status_channel(endpoint.name)) {}

  // Untyped subscriptions: LCM's typed ones drop undecodable messages with a line on stderr, and
  // those must be counted.
  void handle_setpoint(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    owner->on_setpoint(*this, rbuf->data, rbuf->data_size);
  }
  void handle_command(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    owner->on_command(*this, rbuf->data, rbuf->data_size);
  }

  LcmBridge* owner;
  AxisPort port;
  MessageAuthenticator::Channel setpoint_auth;
  MessageAuthenticator::Channel command_auth;
  CommandLease lease;
  std::vector<std::pair<std::string, std::int64_t>> acks;  // operator, counter; least recent first
  bool ack_pending = false;
  std::string telemetry_channel_name;
  std::string status_channel_name;
  SenderSeqGaps setpoint_seq;
  SenderSeqGaps command_seq;
  StatusSample latest{};     // the operator thread's latest status
  StatusSample published{};  // what the last STATUS message said
  Clock::time_point next_status{};
  // The rod in the latest telemetry sample, which status repeats under its MACs.
  std::int64_t sample_utime = 0;
  double position_m = 0.0;
  double setpoint_m = 0.0;
  std::int64_t position_age_us = 0;
  bool position_stale = false;
  // Lease takeovers (ACQUIRE with force): how many, and the last one.
  std::int64_t lease_takeovers = 0;
  std::string lease_taken_by;
  std::string lease_taken_from;
  std::int64_t lease_taken_at_us = 0;
};

LcmBridge::LcmBridge(LcmBridgeConfig config)
    : config_(std::move(config)),
      auth_(std::move(config_.auth), wall_clock_us()),
      url_(lcm_url_with_recv_buf(config_.lcm_url, config_.recv_buf_size)) {
  check_config(config_);
  axes_.reserve(config_.axes.size());
  const auto lease_timeout = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(config_.lease_timeout_s));
  for (const auto& endpoint : config_.axes) {
    axes_.push_back(std::make_unique<Axis>(*this, endpoint, config_.rings, auth_,
                                            lease_timeout));
  }

  // LCM's receive sockets get the receive filter as they are bound, inside the subscriptions below.
  if (const auto address = udpm_address(url_)) socket_guard_.emplace(address->port);
  lcm_ = std::make_unique<lcm::LCM>(url_);
  commands_lcm_ = std::make_unique<lcm::LCM>(url_);
  if (!lcm_->good() || !commands_lcm_->good()) {
    throw std::runtime_error("LcmBridge: cannot open LCM at '" + url_ + "'");
  }
  for (auto& axis : axes_) {
    const std::string& name = axis->port.name();
    lcm::Subscription* sp = lcm_->subscribe(setpoint_channel(name), &Axis::handle_setpoint, axis.get());
    lcm::Subscription* cmd = commands_lcm_->subscribe(command_channel(name), &Axis::handle_command, axis.get());
    if (sp == nullptr || cmd == nullptr || sp->setQueueCapacity(config_.subscription_queue_capacity) != 0 ||
        cmd->setQueueCapacity(config_.subscription_queue_capacity) != 0) {
      throw std::runtime_error("LcmBridge: cannot subscribe the channels of axis '" + name + "'");
    }
  }
  if (socket_guard_) socket_guard_->verify();
}

LcmBridge::~LcmBridge() { stop(); }

void LcmBridge::start() {
  if (thread_.joinable()) return;
  stop_requested_.store(false, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
}

void LcmBridge::stop() {
  if (!thread_.joinable()) return;
  stop_requested_.store(true, std::memory_order_release);
  thread_.join();
}

AxisPort& LcmBridge::axis(std::size_t index) { return axes_.at(index)->port; }

const AxisPort& LcmBridge::axis(std::size_t index) const { return axes_.at(index)->port; }

AxisPort* LcmBridge::find_axis(std::string_view name) {
  for (auto& axis : axes_) {
    if (axis->port.name() == name) return &axis->port;
  }
  return nullptr;
}

int LcmBridge::drain() {
  // Setpoints are taken in batches, with the commands drained before each: a command waits at
  // most one batch behind a flood. The whole wake-up is bounded (a few hundred messages, about a
  // millisecond), so status and telemetry, which confirm a command to its sender, still leave
  // between wake-ups: with 8192 per wake-up, a 40 kHz flood held a confirmation back 1.4 s.
  constexpr int kSetpointBatch = 64;
  constexpr int kMaxMessagesPerWake = 256;
  int handled = 0;
  for (;;) {
    int r = 0;
    while (handled < kMaxMessagesPerWake && (r = commands_lcm_->handleTimeout(0)) > 0) ++handled;
    if (r < 0) return -1;
    int batch = 0;
    while (batch < kSetpointBatch && handled < kMaxMessagesPerWake && (r = lcm_->handleTimeout(0)) > 0) {
      ++batch;
      ++handled;
    }
    if (r < 0) return -1;
    if (batch < kSetpointBatch || handled >= kMaxMessagesPerWake) return handled;
  }
}

void LcmBridge::run() {
  const int timeout_ms = static_cast<int>(config_.poll_interval.count());
  std::array<pollfd, 2> fds{pollfd{commands_lcm_->getFileno(), POLLIN, 0}, pollfd{lcm_->getFileno(), POLLIN, 0}};
  bool reported_error = false;
  while (!stop_requested_.load(std::memory_order_acquire)) {
    // Waits for either instance, or the timeout: the loop stays responsive to stop() and to the
    // telemetry ring whatever the incoming traffic.
    const int ready = poll(fds.data(), fds.size(), timeout_ms);
    if ((ready < 0 && errno != EINTR) || (ready > 0 && drain() < 0)) {
      if (!reported_error) {
        std::fprintf(stderr, "hsad: LCM receive failed on %s; retrying every %d ms\n", url_.c_str(), timeout_ms);
        reported_error = true;
      }
      std::this_thread::sleep_for(config_.poll_interval);  // no busy loop on a broken socket
    }
    service_outbound(Clock::now());
  }
}

namespace {

// Decodes and authenticates: the first steps of every incoming message. RejectReason::none when
// `msg` is now an authentic, fresh message.
template <typename LcmMessage>
RejectReason decode_and_authenticate(LcmMessage& msg, const void* data, std::size_t size,
                                     const MessageAuthenticator& auth, MessageAuthenticator::Channel& channel) {
  if (!decode_exact(msg, data, size)) return RejectReason::decode;
  return auth.check(channel, msg, data, size, wall_clock_us());
}

}  // namespace

// Each message is decoded, authenticated, counted for sequence gaps (only authentic ones, so a
// stranger cannot inflate them), validated, and checked against the axis's lease, in that order.
void LcmBridge::on_setpoint(Axis& axis, const void* data, std::size_t size) {
  hsa::setpoint_t msg;
  RejectReason reason = decode_and_authenticate(msg, data, size, auth_, axis.setpoint_auth);
  if (reason == RejectReason::none) {
    axis.port.count_seq_gaps(axis.setpoint_seq.observe(msg.operator_id, msg.seq));
    const Validated<SetpointInput> result = validate_setpoint(msg, axis.port.limits());
    reason = result.reason;
    if (result.ok() && axis.lease.request(msg.operator_id, CommandLease::Request::motion, Clock::now()) ==
                           CommandLease::Outcome::held_by_other) {
      reason = RejectReason::lease_held;
    }
    if (reason == RejectReason::none) {
      axis.port.offer_setpoint(result.msg);
      return;
    }
  }
  axis.port.count_reject(reason);
}

void LcmBridge::on_command(Axis& axis, const void* data, std::size_t size) {
  hsa::command_t msg;
  if (const RejectReason r = decode_and_authenticate(msg, data, size, auth_, axis.command_auth); r != RejectReason::none) {
    axis.port.count_reject(r);
    return;
  }
  axis.port.count_seq_gaps(axis.command_seq.observe(msg.operator_id, msg.seq));
  const Clock::time_point now = Clock::now();

  // The lease's own commands are carried out here; the RT thread never hears of them.
  if (msg.command == hsa::command_t::ACQUIRE || msg.command == hsa::command_t::RELEASE) {
    using Request = CommandLease::Request;
    const Request request = msg.command == hsa::command_t::RELEASE ? Request::release
                            : msg.force                             ? Request::acquire_force
                                                                    : Request::acquire;
    const CommandLease::Outcome outcome = axis.lease.request(msg.operator_id, request, now);
    if (outcome == CommandLease::Outcome::held_by_other) {
      axis.port.count_reject(RejectReason::lease_held);
      return;
    }
    if (outcome == CommandLease::Outcome::taken_over) {
      // In the status too, where every operator sees it, not only in hsad's log.
      ++axis.lease_takeovers;
      axis.lease_taken_by = msg.operator_id;
      axis.lease_taken_from = axis.lease.previous_holder();
      axis.lease_taken_at_us = wall_clock_us();
      std::fprintf(stderr, "hsad: axis %s: operator '%s' took the lease from '%s' (force)\n",
                   axis.port.name().c_str(), msg.operator_id.c_str(), axis.lease.previous_holder().c_str());
    }
    axis.port.count_command_done();
    acknowledge(axis, msg.operator_id, msg.counter);
    return;
  }

  const Validated<AxisCommand> result = validate_command(msg);
  if (!result.ok()) {
    axis.port.count_reject(result.reason);
    return;
  }
  const auto request = result.msg.kind == CommandKind::disable ? CommandLease::Request::disable
                                                               : CommandLease::Request::motion;
  if (axis.lease.request(msg.operator_id, request, now) == CommandLease::Outcome::held_by_other) {
    axis.port.count_reject(RejectReason::lease_held);
    return;
  }
  OperatorCommand command{.command = result.msg, .from = {}};
  std::snprintf(command.from.operator_id, sizeof command.from.operator_id, "%s", msg.operator_id.c_str());
  command.from.counter = msg.counter;
  if (axis.port.offer_command(command)) acknowledge(axis, msg.operator_id, msg.counter);
}

void LcmBridge::acknowledge(Axis& axis, const std::string& operator_id, std::int64_t counter) {
  auto& acks = axis.acks;
  auto it = std::find_if(acks.begin(), acks.end(), [&](const auto& a) { return a.first == operator_id; });
  if (it != acks.end()) {
    acks.erase(it);
  } else if (acks.size() >= kMaxAcks) {
    acks.erase(acks.begin());  // the operator heard from least recently
  }
  acks.emplace_back(operator_id, counter);
  axis.ack_pending = true;  // the sender is waiting for it: the status goes out at once
}

void LcmBridge::service_outbound(Clock::time_point now) {
  for (auto& owned : axes_) {
    Axis& axis = *owned;

    TelemetrySample sample;
    while (axis.port.telemetry_.try_pop(sample)) {
      const hsa::telemetry_t msg = to_lcm(sample);
      lcm_->publish(axis.telemetry_channel_name, &msg);
      AxisPort::bump(axis.port.telemetry_published_);
      axis.sample_utime = msg.utime;
      axis.position_m = msg.position_m;
      axis.setpoint_m = msg.setpoint_m;
      axis.position_age_us = msg.position_age_us;
      axis.position_stale = (msg.stale & hsa::telemetry_t::STALE_POSITION) != 0;
    }

    // Each change goes out as it happened, even several within one drain.
    while (axis.port.status_.try_pop(axis.latest)) {
      if (status_changed(axis.published, axis.latest)) publish_status(axis, now);
    }
    if (now >= axis.next_status || axis.ack_pending) publish_status(axis, now);
  }
}

void LcmBridge::publish_status(Axis& axis, Clock::time_point now) {
  hsa::status_t msg = to_lcm(axis.latest, axis.port.counters(), utime_now());
  msg.auth_required = auth_.required();
  if (!auth_.required()) msg.warning = kAuthOffWarning;
  msg.lease_holder = axis.lease.holder(now);
  msg.lease_remaining_s = std::chrono::duration<double>(axis.lease.remaining(now)).count();
  msg.num_acks = static_cast<std::int16_t>(axis.acks.size());
  for (const auto& [op, counter] : axis.acks) {
    msg.ack_operator.push_back(op);
    msg.ack_counter.push_back(counter);
  }
  axis.ack_pending = false;
  msg.lease_takeovers = axis.lease_takeovers;
  msg.lease_taken_by = axis.lease_taken_by;
  msg.lease_taken_from = axis.lease_taken_from;
  msg.lease_taken_at_us = axis.lease_taken_at_us;
  msg.sample_utime = axis.sample_utime;
  msg.position_m = axis.position_m;
  msg.setpoint_m = axis.setpoint_m;
  msg.position_age_us = axis.position_age_us;
  msg.position_stale = axis.position_stale;
  // Signed for every operator hsad holds a key for, each of whom verifies it with their own
  // (msgs/auth/status_mac.hpp); the stamp lets them refuse an old one sent again.
  msg.system = auth_.system();
  msg.instance = auth_.instance();
  msg.stamp_us = wall_clock_us();
  msgs::sign_status(msg, auth_.keys(), axis.status_channel_name);
  lcm_->publish(axis.status_channel_name, &msg);
  AxisPort::bump(axis.port.status_published_);
  axis.published = axis.latest;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config_.status_rate_hz));
  axis.next_status = now + period;
}

}  // namespace hsa::daemon
