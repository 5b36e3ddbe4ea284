// The "socketcan" driver plugin: channels mapped onto the payload of raw CAN frames (classic, or
// CAN FD) on one Linux CAN interface. Settings: see drivers/socketcan/can_settings.hpp.
//
// Threads. CAN frames are small and the socket buffers them, so the RT thread does the I/O itself
// with non-blocking system calls, each of which either completes at once or fails with EAGAIN.
// read() drains up to max_frames_per_read frames and returns; write() sends the frames that are
// due with MSG_DONTWAIT. Neither allocates, locks, logs or waits.
//
// One small non-RT thread, the output watchdog, runs from on_configure to on_cleanup/on_error:
// while the driver is active and write() has not run for output_timeout_s (a stalled daemon, or
// a driver in error that no longer gets write()), it sends the safe frames (MSG_DONTWAIT), again
// every output_timeout_s, and counts each time in output_timeouts. It never sends while the RT
// side is live: write() raises `rt_writing_` and counts itself before it looks at
// `watchdog_sending_`, the watchdog raises `watchdog_sending_` before it looks at both (all
// seq_cst), so either the watchdog sees the RT side or that write() skips its sends (its frames
// stay due for the next one). The clock starts at the first write() after activation.
//
// make_safe (RT thread) sends every output frame with its safe values at once (MSG_DONTWAIT),
// whatever the watchdog is doing, and latches: write() sends nothing until the next on_activate,
// and the watchdog, seeing no write(), repeats the safe frames every output_timeout_s. make_safe
// takes no part in the handshake above. The handshake keeps a command frame from following the
// watchdog's safe frames; make_safe sends only safe frames, so the two threads may both send them
// and nothing unsafe can come between. Were make_safe to back off while the watchdog is sending,
// a watchdog preempted in that window (the RT thread runs at SCHED_FIFO, the watchdog does not)
// would hold the safe frames back for as long as it is off the CPU, and a watchdog that had just
// backed off from make_safe's raised flag would leave none sent until its next timeout. A safe
// frame the socket refuses (queue full) is counted in tx_dropped and repeated by the watchdog.
//
// Samples and status: see frame_exchange.hpp. Status channels, declared after the configured ones
// (status always ok):
//   length_errors  analog input   received frames with a configured id but the wrong length (or
//                                 CAN FD where classic is configured, or the reverse)
//   error_frames   analog input   error frames from the controller (all classes)
//   tx_dropped     analog input   output frames the socket refused (queue full); retried next write()
//   bus_off        digital input  1 after a bus-off until the controller restarts
//   output_timeouts analog input  times the watchdog sent the safe frames because write() stopped
//
// Driver errors (read/write return IoStatus::error, so the daemon faults): a bus-off; the socket
// reporting an error other than EAGAIN (the interface went down: ENETDOWN); a send failing for
// another reason than a full queue. failure_reason() names the cause (the errno text, and the
// frame for a send). on_error closes the socket; configure again to reopen it.
//
// Lifecycle. on_configure parses the settings and opens the socket (filters set in the kernel),
// so a kernel without CAN, a missing or down interface, or an interface without CAN FD is reported
// at configure with its reason. Nothing is sent before activation. on_activate makes every output
// frame due at the first write(); on_deactivate sends each output frame once more with its safe
// values (bounded wait for room in the queue). on_cleanup closes the socket.
#include <linux/can.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "drivers/clock.hpp"

#include "drivers/driver.hpp"
#include "drivers/plugin_abi.hpp"
#include "drivers/socketcan/can_settings.hpp"
#include "drivers/socketcan/can_socket.hpp"
#include "drivers/socketcan/frame_exchange.hpp"

namespace hsa::io::socketcan {
namespace {

bool queue_full(int error) { return error == EAGAIN || error == EWOULDBLOCK || error == ENOBUFS; }

class SocketCanDriver final : public Driver {
 public:
  // The settings alone: no socket is opened.
  Result check_settings(const toml::table& table) const override {
    return Result::of([&] { (void)parse_can_settings(table); });
  }

  // The interface, and the channels of the frame map (FrameExchange opens nothing).
  Result plan(const toml::table& table, DriverPlan& plan) const override {
    return Result::of([&] {
      const FrameExchange exchange(parse_can_settings(table));
      plan.devices = {"can:" + exchange.settings().interface};
      const auto channels = exchange.channels();
      plan.channels.assign(channels.begin(), channels.end());
    });
  }

  Result on_configure(const toml::table& table) override {
    try {
      auto exchange = std::make_unique<FrameExchange>(parse_can_settings(table));
      socket_ = std::make_unique<CanSocket>(exchange->settings());
      exchange_ = std::move(exchange);
      failure_[0] = '\0';
      watchdog_ = std::jthread([this](std::stop_token stop) { watch_outputs(std::move(stop)); });
    } catch (const std::exception& e) {  // ConfigError, CanSocketError, std::system_error
      release();
      return Result::failure(e.what());
    }
    return Result::success();
  }

  std::span<const ChannelInfo> channels() const override {
    return exchange_ ? exchange_->channels() : std::span<const ChannelInfo>{};
  }

  Result on_activate() override {
    exchange_->reset_outputs();
    safe_latched_ = false;
    live_.store(true, std::memory_order_release);
    return Result::success();
  }

  Result on_deactivate() override {
    live_.store(false, std::memory_order_release);
    const std::string& name = exchange_->settings().interface;
    for (std::size_t k = 0; k < exchange_->output_count(); ++k) {
      const canfd_frame& frame = exchange_->safe_output(k);
      // A normal thread: wait up to 100 ms for room in the queue, twice.
      ssize_t sent = -1;
      int error = 0;
      for (int attempt = 0; attempt < 3 && sent < 0; ++attempt) {
        if (attempt > 0) {
          pollfd p{socket_->fd(), POLLOUT, 0};
          (void)poll(&p, 1, 100);
        }
        sent = send(socket_->fd(), &frame, exchange_->output_mtu(k), MSG_DONTWAIT);
        error = sent < 0 ? errno : 0;
        if (sent < 0 && !queue_full(error)) break;
      }
      if (sent < 0) {
        return Result::failure("safe values of " + exchange_->output_frame(k).describe() +
                               " not sent on '" + name + "': " + std::strerror(error));
      }
    }
    return Result::success();
  }

  Result on_cleanup() override {
    release();
    return Result::success();
  }

  Result on_error() override {
    release();
    return Result::success();
  }

  IoStatus read(Timestamp t, Duration, std::span<ChannelSlot> slots) noexcept override {
    const int fd = socket_->fd();
    const int max_frames = exchange_->settings().max_frames_per_read;
    int error = 0;
    for (int n = 0; n < max_frames; ++n) {
      canfd_frame frame;
      const ssize_t got = recv(fd, &frame, sizeof frame, MSG_DONTWAIT);
      if (got < 0) {
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) error = errno;  // ENETDOWN: interface down
        break;
      }
      if (got != static_cast<ssize_t>(CAN_MTU) && got != static_cast<ssize_t>(CANFD_MTU)) continue;
      exchange_->accept(frame, got == static_cast<ssize_t>(CANFD_MTU), t);
    }
    exchange_->fill_inputs(t, slots);
    if (error != 0) {
      std::snprintf(failure_, sizeof failure_, "receive on '%s': %s", interface(), strerrordesc_np(error));
      return IoStatus::error;
    }
    if (exchange_->bus_off()) {
      std::snprintf(failure_, sizeof failure_, "'%s' is bus-off (error frame class 0x%X)", interface(),
                    static_cast<unsigned>(exchange_->last_error_class()));
      return IoStatus::error;
    }
    return IoStatus::ok;
  }

  IoStatus write(Timestamp t, Duration, std::span<const ChannelSlot> slots) noexcept override {
    if (safe_latched_) return IoStatus::ok;  // make_safe ran: only safe frames until on_activate
    rt_writing_.store(true, std::memory_order_seq_cst);
    writes_.fetch_add(1, std::memory_order_seq_cst);
    IoStatus status = IoStatus::ok;
    // The watchdog is sending the safe frames (it had seen no write() for output_timeout_s):
    // skip this cycle's sends; the frames stay due and go out from the next write().
    if (!watchdog_sending_.load(std::memory_order_seq_cst)) status = send_due(t, slots);
    rt_writing_.store(false, std::memory_order_release);
    return status;
  }

  void make_safe() noexcept override {
    if (!exchange_ || !socket_) return;
    safe_latched_ = true;
    send_safe_frames();  // at once: see the header comment
  }

  std::string_view failure_reason() const noexcept override { return failure_; }

  // The frame exchange's atomics. A failed send's errno text is the RT thread's (failure_reason,
  // once the driver is in error), so the link's own error here is only the controller's bus-off.
  DriverHealth health() const override {
    if (!exchange_) return {};
    DriverHealth h;
    h.link = exchange_->bus_off() ? DriverHealth::Link::down : DriverHealth::Link::up;
    if (exchange_->bus_off()) h.last_error = std::string("CAN interface ") + interface() + ": bus-off";
    h.counters = {{length_errors_channel, exchange_->length_errors()},
                  {error_frames_channel, exchange_->error_frames()},
                  {tx_dropped_channel, exchange_->tx_dropped()},
                  {output_timeouts_channel, exchange_->output_timeouts()}};
    return h;
  }

 private:
  const char* interface() const noexcept { return exchange_->settings().interface.c_str(); }

  IoStatus send_due(Timestamp t, std::span<const ChannelSlot> slots) noexcept {
    const int fd = socket_->fd();
    for (std::size_t k = 0; k < exchange_->output_count(); ++k) {
      const canfd_frame* frame = exchange_->due_output(k, t, slots);
      if (frame == nullptr) continue;
      if (send(fd, frame, exchange_->output_mtu(k), MSG_DONTWAIT) >= 0) {
        exchange_->mark_sent(k, t);
      } else if (queue_full(errno)) {
        exchange_->count_tx_dropped();
      } else {
        std::snprintf(failure_, sizeof failure_, "send of frame 0x%X on '%s': %s",
                      static_cast<unsigned>(frame->can_id & CAN_EFF_MASK), interface(), strerrordesc_np(errno));
        return IoStatus::error;
      }
    }
    return IoStatus::ok;
  }

  // Every output frame once, with its safe values; a frame the socket refuses counts in tx_dropped.
  void send_safe_frames() noexcept {
    for (std::size_t k = 0; k < exchange_->output_count(); ++k) {
      if (send(socket_->fd(), &exchange_->safe_output(k), exchange_->output_mtu(k), MSG_DONTWAIT) < 0) {
        exchange_->count_tx_dropped();
      }
    }
  }

  // The output watchdog (header comment). Wakes four times per output_timeout_s.
  void watch_outputs(std::stop_token stop) {
    const Duration timeout = exchange_->settings().output_timeout;
    const auto tick = std::chrono::nanoseconds(std::max<std::int64_t>(timeout.count() / 4, 50'000));
    bool was_live = false;
    std::uint64_t at_live = 0, seen = 0;
    std::int64_t seen_ns = monotonic_ns();
    while (!stop.stop_requested()) {
      {
        std::unique_lock lock(sleep_mutex_);
        sleep_cv_.wait_for(lock, stop, tick, [] { return false; });
      }
      const bool live = live_.load(std::memory_order_acquire);
      const std::uint64_t writes = writes_.load(std::memory_order_seq_cst);
      const std::int64_t now = monotonic_ns();
      if (live && !was_live) at_live = writes;
      was_live = live;
      if (writes != seen) {
        seen = writes;
        seen_ns = now;
        continue;
      }
      if (!live || writes == at_live || now - seen_ns < timeout.count()) continue;
      watchdog_sending_.store(true, std::memory_order_seq_cst);
      if (!rt_writing_.load(std::memory_order_seq_cst) && writes_.load(std::memory_order_seq_cst) == seen) {
        send_safe_frames();
        exchange_->count_output_timeout();
      }
      watchdog_sending_.store(false, std::memory_order_seq_cst);
      seen_ns = now;  // again after another output_timeout_s without write()
    }
  }

  void release() {
    live_.store(false, std::memory_order_release);
    if (watchdog_.joinable()) {
      watchdog_.request_stop();
      watchdog_.join();
    }
    socket_.reset();
    exchange_.reset();
  }

  std::unique_ptr<FrameExchange> exchange_;
  std::unique_ptr<CanSocket> socket_;
  char failure_[160] = {};  // the cause of the last IoStatus::error (RT thread)
  bool safe_latched_ = false;  // RT thread: make_safe ran, until on_activate
  std::atomic<bool> live_{false};
  std::atomic<bool> rt_writing_{false};
  std::atomic<bool> watchdog_sending_{false};
  std::atomic<std::uint64_t> writes_{0};
  // Only for the watchdog's timed wait, which request_stop() interrupts. Members, because
  // libstdc++'s condition_variable_any allocates when constructed: the running watchdog allocates
  // nothing.
  std::mutex sleep_mutex_;
  std::condition_variable_any sleep_cv_;
  std::jthread watchdog_;
};

}  // namespace
}  // namespace hsa::io::socketcan

HSA_DRIVER_PLUGIN("socketcan", hsa::io::socketcan::SocketCanDriver)
