#include "drivers/socketcan/can_settings.hpp"

#include <linux/can.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string_view>

#include "drivers/settings.hpp"

namespace hsa::io::socketcan {
namespace {

void require(const Settings& s, std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    if (!s.has(key)) throw SettingsError("key '" + s.key_name(key) + "' is required");
  }
}

ByteOrder byte_order(const Settings& s, ByteOrder fallback) {
  if (!s.has("byte_order")) return fallback;
  return s.choice("byte_order", {"little_endian", "big_endian"}, "") == "little_endian"
             ? ByteOrder::little_endian
             : ByteOrder::big_endian;
}

std::string hex(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%X", static_cast<unsigned>(value));
  return text;
}

// The payload lengths a CAN FD frame may have (its DLC codes 0..15).
constexpr int fd_lengths[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};

struct KindInfo {
  std::string_view name;
  ChannelKind kind;
};
constexpr KindInfo input_kinds[] = {
    {"encoder_input", ChannelKind::encoder_input},
    {"analog_input", ChannelKind::analog_input},
    {"digital_input", ChannelKind::digital_input},
};
constexpr KindInfo output_kinds[] = {
    {"analog_output", ChannelKind::analog_output},
    {"digital_output", ChannelKind::digital_output},
};

ChannelMap parse_channel(const toml::node& node, const std::string& path, const FrameMap& frame,
                         ByteOrder default_order) {
  const toml::table* table = node.as_table();
  if (table == nullptr) {
    throw SettingsError("key '" + path.substr(0, path.size() - 1) +
                        "' must be a table ([[frames.channels]])");
  }
  const Settings s(*table, path);
  require(s, {"name", "kind", "byte_offset"});

  ChannelMap c;
  c.info.name = s.string("name", "");
  if (c.info.name.empty()) s.fail("name", "a non-empty string");
  const bool input = frame.direction == Direction::input;
  const std::string kind = input ? s.choice("kind", {"encoder_input", "analog_input", "digital_input"}, "")
                                 : s.choice("kind", {"analog_output", "digital_output"}, "");
  const std::span<const KindInfo> kinds = input ? std::span<const KindInfo>(input_kinds)
                                                : std::span<const KindInfo>(output_kinds);
  c.info.kind = std::find_if(kinds.begin(), kinds.end(), [&](const KindInfo& k) { return k.name == kind; })->kind;
  const bool digital = c.info.kind == ChannelKind::digital_input || c.info.kind == ChannelKind::digital_output;
  if (digital) {
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes"}
                                : std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "safe_value"});
  } else {
    require(s, {"bytes"});
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "byte_order", "signed", "scale", "offset", "unit"}
                                : std::initializer_list<std::string_view>{"name", "kind", "byte_offset", "bytes", "byte_order", "signed", "scale", "offset", "unit", "safe_value"});
  }

  Field& f = c.codec.field;
  f.offset = s.integer_in("byte_offset", 0, 0, frame.length - 1);
  f.size = s.integer_in("bytes", 1, 1, 8);
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
  c.codec.scale = s.number("scale", 1.0);
  if (c.codec.scale == 0.0 || !std::isfinite(c.codec.scale)) s.fail("scale", "a finite, non-zero number");
  c.codec.offset = s.number("offset", 0.0);
  if (!std::isfinite(c.codec.offset)) s.fail("offset", "a finite number");
  c.info.unit = s.string("unit", "1");
  if (!input) {
    c.safe_value = s.number("safe_value", 0.0);
    if (!std::isfinite(c.safe_value)) s.fail("safe_value", "a finite number");
    // The safe value must go out as it is, not saturated into something else.
    const double raw = std::nearbyint((c.safe_value - c.codec.offset) / c.codec.scale);
    if (raw < field_min(f) || raw > field_max(f)) {
      s.fail("safe_value", "a value the " + std::to_string(f.size) + "-byte " +
                               (f.is_signed ? "signed" : "unsigned") + " field can carry after scale and offset");
    }
  }
  return c;
}

FrameMap parse_frame(const toml::node& node, std::size_t index, Duration default_max_age,
                     ByteOrder default_order) {
  const std::string path = "frames[" + std::to_string(index) + "].";
  const toml::table* table = node.as_table();
  if (table == nullptr) throw SettingsError("key 'frames' must be an array of tables ([[frames]])");
  const Settings s(*table, path);
  require(s, {"id", "direction", "length", "channels"});

  FrameMap f;
  f.direction = s.choice("direction", {"input", "output"}, "") == "input" ? Direction::input : Direction::output;
  if (f.direction == Direction::input) {
    s.reject_unknown_keys({"id", "extended", "fd", "direction", "length", "max_age_s", "channels"});
  } else {
    s.reject_unknown_keys({"id", "extended", "fd", "direction", "length", "period_s", "channels"});
  }
  f.extended = s.boolean("extended", false);
  const std::int64_t id = s.integer("id", 0);
  const std::int64_t max_id = f.extended ? CAN_EFF_MASK : CAN_SFF_MASK;
  if (id < 0 || id > max_id) {
    s.fail("id", f.extended ? "a 29-bit CAN id in [0, 0x1FFFFFFF]"
                            : "an 11-bit CAN id in [0, 0x7FF] (set extended = true for a 29-bit id)");
  }
  f.id = static_cast<std::uint32_t>(id);
  f.fd = s.boolean("fd", false);
  if (f.fd) {
    f.length = s.integer_in("length", 0, 1, 64);
    if (std::find(std::begin(fd_lengths), std::end(fd_lengths), f.length) == std::end(fd_lengths)) {
      s.fail("length", "a CAN FD payload length: 1..8, 12, 16, 20, 24, 32, 48 or 64");
    }
  } else {
    const std::int64_t length = s.integer("length", 0);
    if (length < 1 || length > 8) s.fail("length", "an integer in [1, 8] for a classic frame (set fd = true for CAN FD)");
    f.length = static_cast<int>(length);
  }
  if (f.direction == Direction::input) {
    f.max_age = s.has("max_age_s") ? s.duration("max_age_s", 0.0) : default_max_age;
  } else if (s.has("period_s")) {
    f.period = s.duration("period_s", 0.0);
  }

  const toml::array* list = table->get("channels")->as_array();
  if (list == nullptr || list->empty()) s.fail("channels", "a non-empty array of tables ([[frames.channels]])");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string channel_path = path + "channels[" + std::to_string(i) + "].";
    ChannelMap c = parse_channel(*list->get(i), channel_path, f, default_order);
    for (std::size_t j = 0; j < f.channels.size(); ++j) {
      const Field& a = f.channels[j].codec.field;
      const Field& b = c.codec.field;
      if (b.offset < a.offset + a.size && a.offset < b.offset + b.size) {
        throw SettingsError("key '" + channel_path + "byte_offset' must not overlap " + path + "channels[" +
                            std::to_string(j) + "] (" + f.channels[j].info.name + ", bytes " +
                            std::to_string(a.offset) + ".." + std::to_string(a.offset + a.size - 1) +
                            "), got " + std::to_string(b.offset) + " with bytes = " + std::to_string(b.size));
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
  const Settings s(table);
  s.reject_unknown_keys({"interface", "max_frames_per_read", "max_age_s", "output_timeout_s", "byte_order", "frames"});
  if (!s.has("interface")) throw SettingsError("key 'interface' is required (a CAN interface such as \"can0\")");
  CanSettings out;
  out.interface = s.string("interface", "");
  // IFNAMSIZ is 16 with the terminating NUL.
  if (out.interface.empty() || out.interface.size() > 15 || out.interface.find('/') != std::string::npos) {
    s.fail("interface", "a network interface name of 1 to 15 characters");
  }
  out.max_frames_per_read = s.integer_in("max_frames_per_read", 64, 1, 4096);
  const Duration max_age = s.duration("max_age_s", 0.1);
  out.output_timeout = s.duration("output_timeout_s", 0.005);
  if (out.output_timeout >= std::chrono::seconds(60)) s.fail("output_timeout_s", "less than 60 s");
  const ByteOrder order = byte_order(s, ByteOrder::little_endian);

  const toml::node* frames = table.get("frames");
  if (frames == nullptr) throw SettingsError("key 'frames' is required ([[frames]] tables)");
  const toml::array* list = frames->as_array();
  if (list == nullptr || list->empty()) s.fail("frames", "a non-empty array of tables ([[frames]])");
  for (std::size_t i = 0; i < list->size(); ++i) {
    FrameMap f = parse_frame(*list->get(i), i, max_age, order);
    const std::string key = "frames[" + std::to_string(i) + "]";
    for (std::size_t j = 0; j < out.frames.size(); ++j) {
      if (out.frames[j].can_id() == f.can_id()) {
        throw SettingsError("key '" + key + ".id' must be unique, got " + hex(f.id) + " again (frames[" +
                            std::to_string(j) + "])");
      }
    }
    for (std::size_t k = 0; k < f.channels.size(); ++k) {
      const std::string& name = f.channels[k].info.name;
      const std::string name_key = key + ".channels[" + std::to_string(k) + "].name";
      for (const char* reserved : {length_errors_channel, error_frames_channel, tx_dropped_channel, bus_off_channel,
                                  output_timeouts_channel}) {
        if (name == reserved) {
          throw SettingsError("key '" + name_key + "' must not be \"" + name +
                              "\": the driver declares that status channel itself");
        }
      }
      for (const FrameMap& other : out.frames) {
        for (const ChannelMap& c : other.channels) {
          if (c.info.name == name) {
            throw SettingsError("key '" + name_key + "' must be unique, got \"" + name + "\" again (" +
                                other.describe() + ")");
          }
        }
      }
      for (std::size_t m = 0; m < k; ++m) {
        if (f.channels[m].info.name == name) {
          throw SettingsError("key '" + name_key + "' must be unique, got \"" + name + "\" again");
        }
      }
    }
    out.frames.push_back(std::move(f));
  }
  return out;
}

}  // namespace hsa::io::socketcan
