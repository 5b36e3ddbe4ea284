#include "drivers/socketcan/frame_exchange.hpp"

#include <linux/can/error.h>

#include <cmath>
#include <utility>

namespace hsa::io::socketcan {
namespace {

std::span<std::uint8_t> payload(canfd_frame& f, int length) { return {f.data, static_cast<std::size_t>(length)}; }
std::span<const std::uint8_t> payload(const canfd_frame& f) { return {f.data, f.len}; }

}  // namespace

FrameExchange::FrameExchange(CanSettings settings) : settings_(std::move(settings)) {
  // settings_ no longer moves: pointers into it stay valid.
  std::size_t slot = 0;
  for (const FrameMap& f : settings_.frames) {
    const std::size_t first = channel_refs_.size();
    for (const ChannelMap& c : f.channels) {
      channels_.push_back(c.info);
      channel_refs_.push_back({&c, slot++});
    }
    if (f.direction == Direction::input) {
      inputs_.push_back({&f, f.can_id(), first, f.channels.size()});
      continue;
    }
    Output o{&f, first, f.channels.size()};
    o.frame.can_id = f.can_id();
    o.frame.len = static_cast<std::uint8_t>(f.length);
    o.safe = o.frame;
    for (const ChannelMap& c : f.channels) c.codec.encode(c.safe_value, payload(o.safe, f.length));
    outputs_.push_back(o);
  }
  channels_.push_back({length_errors_channel, ChannelKind::analog_input, "1"});
  channels_.push_back({error_frames_channel, ChannelKind::analog_input, "1"});
  channels_.push_back({tx_dropped_channel, ChannelKind::analog_input, "1"});
  channels_.push_back({bus_off_channel, ChannelKind::digital_input, "1"});
  channels_.push_back({output_timeouts_channel, ChannelKind::analog_input, "1"});
  values_.assign(slot, 0.0);
}

void FrameExchange::accept(const canfd_frame& frame, bool fd, Timestamp t) noexcept {
  if ((frame.can_id & CAN_ERR_FLAG) != 0) {
    error_frames_.fetch_add(1, std::memory_order_relaxed);
    last_error_class_ = frame.can_id & CAN_ERR_MASK;
    if ((frame.can_id & CAN_ERR_BUSOFF) != 0) bus_off_.store(true, std::memory_order_relaxed);
    if ((frame.can_id & CAN_ERR_RESTARTED) != 0) bus_off_.store(false, std::memory_order_relaxed);
    return;
  }
  if ((frame.can_id & CAN_RTR_FLAG) != 0) return;
  const std::uint32_t id = frame.can_id & (CAN_EFF_FLAG | CAN_EFF_MASK);
  for (Input& in : inputs_) {
    if (in.can_id != id) continue;
    if (fd != in.map->fd || frame.len != in.map->length) {
      length_errors_.fetch_add(1, std::memory_order_relaxed);
      in.rejected = true;
      return;
    }
    for (std::size_t i = in.first; i < in.first + in.count; ++i) {
      const ChannelRef& c = channel_refs_[i];
      values_[c.slot] = c.map->codec.decode(payload(frame));
    }
    in.received = true;
    in.rejected = false;
    in.stamp = t;
    return;
  }
}

void FrameExchange::fill_inputs(Timestamp t, std::span<ChannelSlot> slots) const noexcept {
  for (const Input& in : inputs_) {
    SampleStatus status = SampleStatus::ok;
    if (!in.received) {
      status = SampleStatus::disconnected;
    } else if (in.rejected || t - in.stamp > in.map->max_age) {
      status = SampleStatus::stale;
    }
    const Timestamp stamp = in.received ? in.stamp : t;
    for (std::size_t i = in.first; i < in.first + in.count; ++i) {
      const std::size_t slot = channel_refs_[i].slot;
      slots[slot] = {values_[slot], stamp, status};
    }
  }
  const std::size_t n = values_.size();
  slots[n] = {static_cast<double>(length_errors()), t, SampleStatus::ok};
  slots[n + 1] = {static_cast<double>(error_frames()), t, SampleStatus::ok};
  slots[n + 2] = {static_cast<double>(tx_dropped()), t, SampleStatus::ok};
  slots[n + 3] = {bus_off() ? 1.0 : 0.0, t, SampleStatus::ok};
  slots[n + 4] = {static_cast<double>(output_timeouts()), t, SampleStatus::ok};
}

const canfd_frame* FrameExchange::due_output(std::size_t k, Timestamp t,
                                             std::span<const ChannelSlot> slots) noexcept {
  Output& o = outputs_[k];
  if (o.sent && t - o.last_sent < o.map->period) return nullptr;
  const std::span<std::uint8_t> data = payload(o.frame, o.map->length);
  for (std::size_t i = o.first; i < o.first + o.count; ++i) {
    const ChannelRef& c = channel_refs_[i];
    const double value = slots[c.slot].value;
    c.map->codec.encode(std::isnan(value) ? c.map->safe_value : value, data);
  }
  return &o.frame;
}

void FrameExchange::mark_sent(std::size_t k, Timestamp t) noexcept {
  outputs_[k].sent = true;
  outputs_[k].last_sent = t;
}

std::size_t FrameExchange::output_mtu(std::size_t k) const noexcept {
  return outputs_[k].map->fd ? CANFD_MTU : CAN_MTU;
}

void FrameExchange::reset_outputs() noexcept {
  for (Output& o : outputs_) o.sent = false;
}

}  // namespace hsa::io::socketcan
