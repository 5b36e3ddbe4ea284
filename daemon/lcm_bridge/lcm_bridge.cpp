#include "daemon/lcm_bridge/lcm_bridge.hpp"
#include "daemon/lcm_bridge/lcm_receive_filter.hpp"

#include <poll.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <utility>

#include <lcm/lcm-cpp.hpp>

#include "daemon/lcm_bridge/message_conversion.hpp"
#include "daemon/lcm_bridge/seq_gap_counter.hpp"
#include "daemon/lcm_bridge/tick_decimator.hpp"

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

// rt_tick_hz / telemetry_rate_hz as an integer, or throws: a rate that does not divide the tick
// would publish unevenly.
std::uint64_t decimation_factor(const LcmBridgeConfig& c, const AxisEndpoint& axis) {
  const double rate_hz = axis.telemetry_rate_hz > 0.0 ? axis.telemetry_rate_hz : c.telemetry_rate_hz;
  if (!positive_finite(c.rt_tick_hz) || !positive_finite(rate_hz)) {
    throw std::invalid_argument("LcmBridge: rt_tick_hz and telemetry_rate_hz must be positive");
  }
  const double ratio = c.rt_tick_hz / rate_hz;
  const double rounded = std::round(ratio);
  if (rounded < 1.0 || std::fabs(ratio - rounded) > 1e-9 * rounded) {
    throw std::invalid_argument("LcmBridge: telemetry_rate_hz must divide rt_tick_hz (got " + std::to_string(rate_hz) +
                                " Hz for a " + std::to_string(c.rt_tick_hz) + " Hz tick, axis '" + axis.name + "')");
  }
  return static_cast<std::uint64_t>(rounded);
}

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
  Axis(LcmBridge& bridge, const AxisEndpoint& endpoint, const RingCapacities& rings, std::uint64_t decimation)
      : owner(&bridge),
        port(endpoint.name, endpoint.limits, rings),
        telemetry_channel_name(telemetry_channel(endpoint.name)),
        status_channel_name(status_channel(endpoint.name)),
        decimator(decimation) {}

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
  std::string telemetry_channel_name;
  std::string status_channel_name;
  SeqGapCounter setpoint_seq;
  SeqGapCounter command_seq;
  TickDecimator decimator;
  StatusSample latest{};     // the RT side's latest status
  StatusSample published{};  // what the last STATUS message said
  Clock::time_point next_status{};
};

LcmBridge::LcmBridge(LcmBridgeConfig config)
    : config_(std::move(config)),
      url_(lcm_url_with_recv_buf(config_.lcm_url, config_.recv_buf_size)) {
  check_config(config_);
  axes_.reserve(config_.axes.size());
  for (const auto& endpoint : config_.axes) {
    axes_.push_back(std::make_unique<Axis>(*this, endpoint, config_.rings, decimation_factor(config_, endpoint)));
  }

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
  // The subscriptions opened LCM's receive socket: only small unfragmented datagrams may reach it.
  if (const auto port = udpm_port(url_); port && limit_lcm_receive(*port) == 0) {
    throw std::runtime_error("LcmBridge: LCM's receive socket on port " + std::to_string(*port) +
                             " was not found, so its size limit cannot be set");
  }
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

std::uint64_t LcmBridge::telemetry_decimation(std::size_t index) const { return axes_.at(index)->decimator.factor(); }
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

void LcmBridge::on_setpoint(Axis& axis, const void* data, std::size_t size) {
  const DecodedSetpoint d = decode_setpoint(data, size, axis.port.limits());
  if (d.decoded) axis.port.count_seq_gaps(axis.setpoint_seq.observe(d.seq));
  if (!d.result.ok()) {
    axis.port.count_reject(d.result.reason);
    return;
  }
  axis.port.offer_setpoint(d.result.msg);
}

void LcmBridge::on_command(Axis& axis, const void* data, std::size_t size) {
  const DecodedCommand d = decode_command(data, size);
  if (d.decoded) axis.port.count_seq_gaps(axis.command_seq.observe(d.seq));
  if (!d.result.ok()) {
    axis.port.count_reject(d.result.reason);
    return;
  }
  axis.port.offer_command(d.result.msg);
}

void LcmBridge::service_outbound(Clock::time_point now) {
  for (auto& owned : axes_) {
    Axis& axis = *owned;

    TelemetrySample sample;
    while (axis.port.telemetry_.try_pop(sample)) {
      if (!axis.decimator.take(sample.tick)) continue;
      const hsa::telemetry_t msg = to_lcm(sample);
      lcm_->publish(axis.telemetry_channel_name, &msg);
      AxisPort::bump(axis.port.telemetry_published_);
    }

    // Each change goes out as it happened, even several within one drain.
    while (axis.port.status_.try_pop(axis.latest)) {
      if (status_changed(axis.published, axis.latest)) publish_status(axis, now);
    }
    if (now >= axis.next_status) publish_status(axis, now);
  }
}

void LcmBridge::publish_status(Axis& axis, Clock::time_point now) {
  const hsa::status_t msg = to_lcm(axis.latest, axis.port.counters(), utime_now());
  lcm_->publish(axis.status_channel_name, &msg);
  AxisPort::bump(axis.port.status_published_);
  axis.published = axis.latest;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config_.status_rate_hz));
  axis.next_status = now + period;
}

}  // namespace hsa::daemon
