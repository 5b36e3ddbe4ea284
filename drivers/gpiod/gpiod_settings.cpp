#include "drivers/gpiod/gpiod_settings.hpp"

#include <string_view>

#include "drivers/settings.hpp"

namespace hsa::io::gpiod {
namespace {

Bias bias_from(std::string_view name) {
  if (name == "disable") return Bias::disable;
  if (name == "pull_up") return Bias::pull_up;
  if (name == "pull_down") return Bias::pull_down;
  return Bias::as_is;
}

Drive drive_from(std::string_view name) {
  if (name == "open_drain") return Drive::open_drain;
  if (name == "open_source") return Drive::open_source;
  return Drive::push_pull;
}

// The line key: a name (non-empty string) or an offset (integer in [0, 2^32)).
void parse_line(const Settings& s, LineAddress& a) {
  constexpr const char* expected = "a line name (string) or offset (integer >= 0)";
  const toml::node* node = s.table().get("line");
  if (const auto* name = node->as_string()) {
    a.by_name = true;
    a.name = name->get();
    if (a.name.empty()) s.fail("line", expected);
  } else if (const auto* offset = node->as_integer()) {
    if (offset->get() < 0 || offset->get() > 0xffffffffLL) s.fail("line", expected);
    a.by_name = false;
    a.offset = static_cast<unsigned int>(offset->get());
  } else {
    s.fail("line", expected);
  }
}

LineChannel parse_channel(const toml::node& node, std::size_t index, const std::string& default_chip) {
  const std::string path = "channels[" + std::to_string(index) + "].";
  const toml::table* table = node.as_table();
  if (table == nullptr) throw SettingsError("key 'channels' must be an array of tables ([[channels]])");
  const Settings s(*table, path);
  for (const char* key : {"name", "kind", "line"}) {
    if (!s.has(key)) throw SettingsError("key '" + s.key_name(key) + "' is required");
  }

  LineChannel c;
  c.info.name = s.string("name", "");
  if (c.info.name.empty()) s.fail("name", "a non-empty string");
  c.info.kind = s.choice("kind", {"digital_input", "digital_output"}, "") == "digital_input"
                    ? ChannelKind::digital_input
                    : ChannelKind::digital_output;
  c.info.unit = "1";
  const bool input = c.info.kind == ChannelKind::digital_input;
  if (input) {
    s.reject_unknown_keys({"name", "kind", "chip", "line", "active_low", "bias", "edge_events"});
  } else {
    s.reject_unknown_keys(
        {"name", "kind", "chip", "line", "active_low", "bias", "drive", "safe_value", "charge_pump", "divisor"});
  }

  if (s.has("chip")) {
    c.address.chip = s.string("chip", "");
    c.address.chip_key = s.key_name("chip");
    if (c.address.chip.empty()) s.fail("chip", "a GPIO chip name, /dev path, label or number");
  } else if (!default_chip.empty()) {
    c.address.chip = default_chip;
    c.address.chip_key = "chip";
  } else {
    throw SettingsError("key '" + s.key_name("chip") +
                        "' is required when there is no top-level 'chip' (a GPIO chip name like "
                        "\"gpiochip0\", a /dev path, a label or a number)");
  }
  parse_line(s, c.address);
  c.address.line_key = s.key_name("line");

  c.active_low = s.boolean("active_low", false);
  c.bias = bias_from(s.choice("bias", {"as_is", "disable", "pull_up", "pull_down"}, "as_is"));
  if (input) {
    c.edge_events = s.boolean("edge_events", false);
  } else {
    c.drive = drive_from(s.choice("drive", {"push_pull", "open_drain", "open_source"}, "push_pull"));
    c.safe_value = s.boolean("safe_value", false);
    c.charge_pump = s.boolean("charge_pump", false);
    if (s.has("divisor") && !c.charge_pump) {
      throw SettingsError("key '" + s.key_name("divisor") +
                          "' applies only to a charge pump: set charge_pump = true, or remove it");
    }
    c.divisor = static_cast<std::uint32_t>(s.integer_in("divisor", 1, 1, 1'000'000));
  }
  return c;
}

bool same_line(const LineAddress& a, const LineAddress& b) {
  if (a.chip != b.chip || a.by_name != b.by_name) return false;
  return a.by_name ? a.name == b.name : a.offset == b.offset;
}

}  // namespace

std::string LineAddress::describe() const {
  return by_name ? "line '" + name + "'" : "line " + std::to_string(offset);
}

GpiodSettings parse_gpiod_settings(const toml::table& table) {
  const Settings s(table);
  s.reject_unknown_keys({"chip", "channels"});
  const std::string chip = s.string("chip", "");
  if (s.has("chip") && chip.empty()) s.fail("chip", "a GPIO chip name, /dev path, label or number");

  const toml::node* channels = table.get("channels");
  if (channels == nullptr) throw SettingsError("key 'channels' is required ([[channels]] tables)");
  const toml::array* list = channels->as_array();
  if (list == nullptr || list->empty()) s.fail("channels", "a non-empty array of tables ([[channels]])");

  GpiodSettings out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    LineChannel c = parse_channel(*list->get(i), i, chip);
    const std::string key = "channels[" + std::to_string(i) + "]";
    for (std::size_t j = 0; j < out.channels.size(); ++j) {
      const LineChannel& o = out.channels[j];
      if (o.info.name == c.info.name) {
        throw SettingsError("key '" + key + ".name' must be unique, got \"" + c.info.name +
                            "\" again (channels[" + std::to_string(j) + "])");
      }
      // Only the obvious duplicate is caught here; the same line reached by name and by offset,
      // or through two spellings of one chip, is caught when the lines are resolved.
      if (same_line(o.address, c.address)) {
        throw SettingsError("key '" + key + ".line' must name a line no other channel uses, got " +
                            c.address.describe() + " of chip '" + c.address.chip +
                            "' again (channels[" + std::to_string(j) + "], " + o.info.name + ")");
      }
    }
    out.channels.push_back(std::move(c));
  }
  return out;
}

}  // namespace hsa::io::gpiod
