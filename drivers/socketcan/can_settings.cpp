#include "drivers/socketcan/can_settings.hpp"

#include <linux/can.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>
#include <vector>
#include <string_view>

#include "drivers/table_reader.hpp"

namespace hsa::io::socketcan {
namespace {

ByteOrder byte_order(const TableReader& s, ByteOrder fallback) {
  const std::string order = s.choice("byte_order", {"little_endian", "big_endian"},
                                     fallback == ByteOrder::little_endian ? "little_endian" : "big_endian");
  return order == "little_endian" ? ByteOrder::little_endian : ByteOrder::big_endian;
}

std::string hex(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%X", static_cast<unsigned>(value));
  return text;
}

// The payload lengths a CAN FD frame may have (its DLC codes 0..15).
constexpr int fd_lengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

ChannelMap parse_channel(const TableReader& s, const FrameMap& frame, ByteOrder default_order) {
  ChannelMap c;
  c.info.name = s.string("name", "a non-empty string");
  if (c.info.name.empty()) s.fail("name", "a non-empty string");
  const bool input = frame.direction == Direction::input;
  const std::string kind = input ? s.choice("kind", {"encoder_input", "analog_input", "digital_input"})
                                 : s.choice("kind", {"analog_output", "digital_output"});
  c.info.kind = *channel_kind_named(kind);  // choice() admitted only kinds
  const bool digital = c.info.kind == ChannelKind::digital_input || c.info.kind == ChannelKind::digital_output;
  if (digital) {
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes"}
                                : std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "safe_value"});
  } else {
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "byte_order", "signed", "scale", "offset", "unit"}
                                : std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "byte_order", "signed", "scale", "offset", "unit", "safe_value"});
  }

  Field& f = c.codec.field;
  f.offset = static_cast<int>(s.integer("byte_offset", 0, frame.length - 1));
  // A digital channel is one byte unless it says otherwise; a number's width must be given.
  f.size = static_cast<int>(digital ? s.integer("bytes", 1, 8, 1) : s.integer("bytes", 1, 8));
  if (f.offset + f.size > frame.length) {
    s.fail("bytes", "at most " + std::to_string(frame.length - f.offset) + " to fit in the frame's " +
                        std::to_string(frame.length) + " bytes from byte_offset " + std::to_string(f.offset));
  }
  c.codec.digital = digital;
  if (digital) {
    c.info.unit = "1";
    if (!input) c.safe_value = s.boolean("safe_value", false) ? 1.0 : 0.0;
    return c;
  }
  f.order = byte_order(s, default_order);
  f.is_signed = s.boolean("signed", false);
  c.codec.scale = s.number("scale", NumberRange::any(), 1.0);
  if (c.codec.scale == 0.0) s.fail("scale", "a finite, non-zero number");
  c.codec.offset = s.number("offset", NumberRange::any(), 0.0);
  c.info.unit = s.string("unit", "a unit such as \"m\" or \"Pa\"", "1");
  if (!input) {
    c.safe_value = s.number("safe_value", NumberRange::any(), 0.0);
    // The safe value must go out as it is, not saturated into something else.
    const double raw = std::nearbyint((c.safe_value - c.codec.offset) / c.codec.scale);
    if (raw < field_min(f) || raw > field_max(f)) {
      s.fail("safe_value", "a value the " + std::to_string(f.size) + "-byte " +
                               (f.is_signed ? "signed" : "unsigned") + " field can carry after scale and offset");
    }
  }
  return c;
}

// Fails unless `name` is free: not a status channel the driver declares, nor a channel of an
// earlier frame (`frames`) or an earlier channel of this one (`channels`).
void check_channel_name(const TableReader& s, const std::string& name, const std::vector<FrameMap>& frames,
                        const std::vector<ChannelMap>& channels) {
  for (const char* reserved :
       {length_errors_channel, error_frames_channel, tx_dropped_channel, bus_off_channel, output_timeouts_channel}) {
    if (name == reserved) s.fail("name", "a name other than \"" + name + "\", a status channel the driver declares itself");
  }
  for (const FrameMap& other : frames) {
    for (const ChannelMap& c : other.channels) {
      if (c.info.name == name) s.fail("name", "a name no other channel has (" + other.describe() + " has one)");
    }
  }
  for (std::size_t m = 0; m < channels.size(); ++m) {
    if (channels[m].info.name == name) {
      s.fail("name", "a name no other channel has (channels[" + std::to_string(m) + "] of this frame has it)");
    }
  }
}

FrameMap parse_frame(const TableReader& s, const std::vector<FrameMap>& earlier, Duration default_max_age,
                     ByteOrder default_order) {
  FrameMap f;
  f.direction = s.choice("direction", {"input", "output"}) == "input" ? Direction::input : Direction::output;
  if (f.direction == Direction::input) {
    s.reject_unknown_keys({"id", "extended", "fd", "direction", "length", "max_age_s", "channels"});
  } else {
    s.reject_unknown_keys({"id", "extended", "fd", "direction", "length", "period_s", "channels"});
  }
  f.extended = s.boolean("extended", false);
  const std::int64_t max_id = f.extended ? CAN_EFF_MASK : CAN_SFF_MASK;
  const std::string id_expected = f.extended
                                      ? "a 29-bit CAN id in [0, 0x1FFFFFFF]"
                                      : "an 11-bit CAN id in [0, 0x7FF] (set extended = true for a 29-bit id)";
  const std::optional<std::int64_t> id = s.table()["id"].value_exact<std::int64_t>();
  if (!id || *id < 0 || *id > max_id) s.fail("id", id_expected);
  f.id = static_cast<std::uint32_t>(*id);
  for (std::size_t j = 0; j < earlier.size(); ++j) {
    if (earlier[j].can_id() == f.can_id()) {
      s.fail("id", "an id no other frame has (frames[" + std::to_string(j) + "] is " + hex(f.id) + ")");
    }
  }
  f.fd = s.boolean("fd", false);
  if (f.fd) {
    f.length = static_cast<int>(s.integer("length", 1, 64));
    if (std::find(std::begin(fd_lengths), std::end(fd_lengths), f.length) == std::end(fd_lengths)) {
      s.fail("length", "a CAN FD payload length: 1..8, 12, 16, 20, 24, 32, 48 or 64");
    }
  } else {
    const std::optional<std::int64_t> length = s.table()["length"].value_exact<std::int64_t>();
    if (!length || *length < 1 || *length > 8) {
      s.fail("length", "an integer in [1, 8] for a classic frame (set fd = true for CAN FD)");
    }
    f.length = static_cast<int>(*length);
  }
  if (f.direction == Direction::input) {
    f.max_age = s.has("max_age_s") ? s.duration("max_age_s", NumberRange::positive()) : default_max_age;
  } else if (s.has("period_s")) {
    f.period = s.duration("period_s", NumberRange::positive());
  }

  const std::vector<TableReader> channels = s.tables("channels");
  if (channels.empty()) s.fail("channels", "a non-empty array of tables ([[frames.channels]])");
  for (const TableReader& t : channels) {
    ChannelMap c = parse_channel(t, f, default_order);
    check_channel_name(t, c.info.name, earlier, f.channels);
    for (std::size_t j = 0; j < f.channels.size(); ++j) {
      const Field& a = f.channels[j].codec.field;
      const Field& b = c.codec.field;
      if (b.offset < a.offset + a.size && a.offset < b.offset + b.size) {
        t.fail("byte_offset", "bytes that do not overlap channels[" + std::to_string(j) + "] (" +
                                  f.channels[j].info.name + ", bytes " + std::to_string(a.offset) + ".." +
                                  std::to_string(a.offset + a.size - 1) + ") with bytes = " + std::to_string(b.size));
      }
    }
    f.channels.push_back(std::move(c));
  }
  return f;
}

}  // namespace

std::uint32_t FrameMap::can_id() const { return extended ? (id | CAN_EFF_FLAG) : id; }

std::string FrameMap::describe() const {
  return "frame " + hex(id) + (extended ? " (extended)" : "");
}

bool CanSettings::uses_fd() const {
  return std::any_of(frames.begin(), frames.end(), [](const FrameMap& f) { return f.fd; });
}

CanSettings parse_can_settings(const toml::table& table) {
  const TableReader s = TableReader::of(table);
  s.reject_unknown_keys({"interface", "max_frames_per_read", "max_age_s", "output_timeout_s", "byte_order", "frames"});
  CanSettings out;
  constexpr std::string_view interface_expected = "a CAN network interface name of 1 to 15 characters, such as \"can0\"";
  out.interface = s.string("interface", interface_expected);
  // IFNAMSIZ is 16 with the terminating NUL.
  if (out.interface.empty() || out.interface.size() > 15 || out.interface.find('/') != std::string::npos) {
    s.fail("interface", interface_expected);
  }
  out.max_frames_per_read = static_cast<int>(s.integer("max_frames_per_read", 1, 4096, 64));
  const Duration max_age = s.duration("max_age_s", NumberRange::positive(), 0.1);
  // Seconds in (0, 60): a timeout of a minute or more is a typo for milliseconds, not a setting.
  out.output_timeout = s.duration(
      "output_timeout_s", NumberRange{.min = 0.0, .max = 60.0, .min_exclusive = true, .max_exclusive = true}, 0.005);
  const ByteOrder order = byte_order(s, ByteOrder::little_endian);

  const std::vector<TableReader> frames = s.tables("frames");
  if (frames.empty()) s.fail("frames", "a non-empty array of tables ([[frames]])");
  for (const TableReader& t : frames) out.frames.push_back(parse_frame(t, out.frames, max_age, order));
  return out;
}

}  // namespace hsa::io::socketcan
