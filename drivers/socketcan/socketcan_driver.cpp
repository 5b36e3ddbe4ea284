// The "socketcan" driver plugin: channels mapped onto the payload of raw CAN frames (classic, or
// CAN FD) on one Linux CAN interface. Settings: see drivers/socketcan/can_settings.hpp.
//
// Threads. None of its own: CAN frames are small and the socket buffers them, so the RT thread
// does the I/O itself with non-blocking system calls, each of which either completes at once or
// fails with EAGAIN. read() drains up to max_frames_per_read frames and returns; write() sends
// the frames that are due with MSG_DONTWAIT. Neither allocates, locks, logs or waits.
//
// Samples and status: see frame_exchange.hpp. Status channels, declared after the configured ones
// (status always ok):
//   length_errors  analog input   received frames with a configured id but the wrong length (or
//                                 CAN FD where classic is configured, or the reverse)
//   error_frames   analog input   error frames from the controller (all classes)
//   tx_dropped     analog input   output frames the socket refused (queue full); retried next write()
//   bus_off        digital input  1 after a bus-off until the controller restarts
//
// Driver errors (read/write return IoStatus::error, so the daemon faults): a bus-off; the socket
// reporting an error other than EAGAIN (the interface went down: ENETDOWN); a send failing for
// another reason than a full queue. on_error closes the socket; configure again to reopen it.
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

#include <cerrno>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "drivers/driver.hpp"
#include "drivers/plugin_abi.hpp"
#include "drivers/settings.hpp"
#include "drivers/socketcan/can_settings.hpp"
#include "drivers/socketcan/can_socket.hpp"
#include "drivers/socketcan/frame_exchange.hpp"

namespace hsa::io::socketcan {
namespace {

bool queue_full(int error) { return error == EAGAIN || error == EWOULDBLOCK || error == ENOBUFS; }

class SocketCanDriver final : public Driver {
 public:
  Result on_configure(const toml::table& table) override {
    try {
      auto exchange = std::make_unique<FrameExchange>(parse_can_settings(table));
      socket_ = std::make_unique<CanSocket>(exchange->settings());
      exchange_ = std::move(exchange);
    } catch (const std::exception& e) {  // SettingsError, CanSocketError
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
    return Result::success();
  }

  Result on_deactivate() override {
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
    bool failed = false;
    for (int n = 0; n < max_frames; ++n) {
      canfd_frame frame;
      const ssize_t got = recv(fd, &frame, sizeof frame, MSG_DONTWAIT);
      if (got < 0) {
        failed = errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;  // ENETDOWN: interface down
        break;
      }
      if (got != static_cast<ssize_t>(CAN_MTU) && got != static_cast<ssize_t>(CANFD_MTU)) continue;
      exchange_->accept(frame, got == static_cast<ssize_t>(CANFD_MTU), t);
    }
    exchange_->fill_inputs(t, slots);
    return failed || exchange_->bus_off() ? IoStatus::error : IoStatus::ok;
  }

  IoStatus write(Timestamp t, Duration, std::span<const ChannelSlot> slots) noexcept override {
    const int fd = socket_->fd();
    for (std::size_t k = 0; k < exchange_->output_count(); ++k) {
      const canfd_frame* frame = exchange_->due_output(k, t, slots);
      if (frame == nullptr) continue;
      if (send(fd, frame, exchange_->output_mtu(k), MSG_DONTWAIT) >= 0) {
        exchange_->mark_sent(k, t);
      } else if (queue_full(errno)) {
        exchange_->count_tx_dropped();
      } else {
        return IoStatus::error;
      }
    }
    return IoStatus::ok;
  }

 private:
  void release() {
    socket_.reset();
    exchange_.reset();
  }

  std::unique_ptr<FrameExchange> exchange_;
  std::unique_ptr<CanSocket> socket_;
};

}  // namespace
}  // namespace hsa::io::socketcan

HSA_DRIVER_PLUGIN("socketcan", hsa::io::socketcan::SocketCanDriver)
