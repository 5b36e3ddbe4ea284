// The socketcan plugin's real-time bookkeeping, with no socket in it: which received frame feeds
// which channels, how old each input frame is, which output frames are due, and the error
// counters. The driver does the system calls and hands every frame it reads to accept(); tests
// hand it frames directly, so all of this is checked without a CAN kernel.
//
// Receive (accept):
//   - an error frame (CAN_ERR_FLAG) is counted; CAN_ERR_BUSOFF latches bus_off until a frame
//     with CAN_ERR_RESTARTED arrives (the controller was restarted);
//   - a data frame with a configured input id and the configured length and format (classic or
//     FD) is decoded into its channels' values, stamped with the cycle time `t` of the read()
//     that drained it;
//   - one with the wrong length or format is counted in length_errors and changes no value: the
//     frame's channels read stale until a valid frame arrives again;
//   - anything else (remote frames, ids the kernel filter should have dropped) is ignored.
// Input status: disconnected until the first valid frame, stale after a rejected frame or when
// the last valid one is older than the frame's max_age, ok otherwise. A channel's timestamp is
// that of the frame that gave its value, so it changes exactly when the value is new.
//
// Send (due_output): an output frame is due on the first write() and then whenever `period` has
// passed since it was last sent (every write() when period is zero). Its payload is built from
// the slot values; a NaN command goes out as the channel's safe value.
//
// Everything is allocated in the constructor; accept, fill_inputs and due_output allocate
// nothing, lock nothing and make no system call.
#pragma once

#include <linux/can.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/socketcan/can_settings.hpp"

namespace hsa::io::socketcan {

class FrameExchange {
 public:
  explicit FrameExchange(CanSettings settings);
  // It points into its own settings: not copyable or movable (hold it by unique_ptr).
  FrameExchange(const FrameExchange&) = delete;
  FrameExchange& operator=(const FrameExchange&) = delete;

  [[nodiscard]] const CanSettings& settings() const noexcept { return settings_; }
  // The configured channels in order (frame by frame), then the five status channels.
  [[nodiscard]] std::span<const ChannelInfo> channels() const { return channels_; }

  // One frame read from the socket; `fd` when it was read as a CAN FD frame (CANFD_MTU bytes).
  void accept(const canfd_frame& frame, bool fd, Timestamp t) noexcept;
  // Fills the input channels' slots and the status channels'.
  void fill_inputs(Timestamp t, std::span<ChannelSlot> slots) const noexcept;

  [[nodiscard]] std::size_t output_count() const noexcept { return outputs_.size(); }
  // Output frame `k` if it is due at `t`, its payload built from `slots`; nullptr when not due.
  // Call mark_sent once the socket took it (a frame the socket refused stays due).
  const canfd_frame* due_output(std::size_t k, Timestamp t, std::span<const ChannelSlot> slots) noexcept;
  void mark_sent(std::size_t k, Timestamp t) noexcept;
  // Output frame `k` carrying its channels' safe values.
  [[nodiscard]] const canfd_frame& safe_output(std::size_t k) const noexcept { return outputs_[k].safe; }
  [[nodiscard]] const FrameMap& output_frame(std::size_t k) const { return *outputs_[k].map; }
  // Bytes to write for output frame `k`: CAN_MTU or CANFD_MTU.
  [[nodiscard]] std::size_t output_mtu(std::size_t k) const noexcept;
  // Forget when outputs were last sent, so the next write() sends every frame (on activation).
  void reset_outputs() noexcept;

  void count_tx_dropped() noexcept { tx_dropped_.fetch_add(1, std::memory_order_relaxed); }
  // From the plugin's watchdog thread: it sent the safe frames because write() had stopped.
  void count_output_timeout() noexcept { output_timeouts_.fetch_add(1, std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t output_timeouts() const noexcept {
    return output_timeouts_.load(std::memory_order_relaxed);
  }
  // Any thread: the RT thread counts, the operator thread reads them for the driver's health.
  [[nodiscard]] bool bus_off() const noexcept { return bus_off_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t length_errors() const noexcept { return length_errors_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t error_frames() const noexcept { return error_frames_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t tx_dropped() const noexcept { return tx_dropped_.load(std::memory_order_relaxed); }
  // The can_id (class bits) of the last error frame, 0 if none: for the message on_error gives.
  [[nodiscard]] std::uint32_t last_error_class() const noexcept { return last_error_class_; }

 private:
  struct ChannelRef {
    const ChannelMap* map;
    std::size_t slot;
  };
  struct Input {
    const FrameMap* map;
    std::uint32_t can_id;
    std::size_t first;  // its channels are channel_refs_[first, first + count)
    std::size_t count;
    bool received = false;  // a valid frame has arrived
    bool rejected = false;  // the last frame with this id had the wrong length or format
    Timestamp stamp{};      // the cycle time of the last valid frame
  };
  struct Output {
    const FrameMap* map;
    std::size_t first;
    std::size_t count;
    canfd_frame frame{};  // built in place each time it is due
    canfd_frame safe{};
    bool sent = false;
    Timestamp last_sent{};
  };

  CanSettings settings_;
  std::vector<ChannelInfo> channels_;
  std::vector<ChannelRef> channel_refs_;
  std::vector<double> values_;  // decoded input values, indexed by slot
  std::vector<Input> inputs_;
  std::vector<Output> outputs_;
  std::atomic<std::uint64_t> length_errors_{0};
  std::atomic<std::uint64_t> error_frames_{0};
  std::atomic<std::uint64_t> tx_dropped_{0};
  std::atomic<std::uint64_t> output_timeouts_{0};  // the watchdog thread counts, the RT thread reads
  std::uint32_t last_error_class_ = 0;
  std::atomic<bool> bus_off_{false};
};

}  // namespace hsa::io::socketcan
