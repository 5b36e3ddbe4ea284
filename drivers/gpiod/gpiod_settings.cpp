#include "drivers/gpiod/gpiod_settings.hpp"

#include <string_view>

#include "drivers/table_reader.hpp"

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
void parse_line(const TableReader& s, LineAddress& a) {
  constexpr const char* expected = "a line name (string) or offset (integer >= 0)";
  const toml::node* node = s.table().get("line");
  if (node == nullptr) s.fail("line", expected);
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

LineChannel parse_channel(const TableReader& s, const std::string& default_chip) {
  LineChannel c;
  c.info.name = s.string("name", "a non-empty string");
  if (c.info.name.empty()) s.fail("name", "a non-empty string");
  c.info.kind = s.choice("kind", {"digital_input", "digital_output"}) == "digital_input"
                    ? ChannelKind::digital_input
                    : ChannelKind::digital_output;
  c.info.unit = "1";
  const bool input = c.info.kind == ChannelKind::digital_input;
  if (input) {
    s.reject_unknown_keys({"name", "kind", "chip", "line", "active_low", "bias", "edge_events"});
  } else {
    s.reject_unknown_keys(
        {"name", "kind", "chip", "line", "active_low", "bias", "drive", "safe_value", "charge_pump", "divisor",
         "enabled_by"});
  }

  if (s.has("chip") || default_chip.empty()) {
    c.address.chip = s.string("chip", "a GPIO chip name like \"gpiochip0\", a /dev path, a label or a number "
                                      "(here or as the top-level chip)");
    c.address.chip_key = s.key_path("chip");
    if (c.address.chip.empty()) s.fail("chip", "a GPIO chip name, /dev path, label or number");
  } else {
    c.address.chip = default_chip;
    c.address.chip_key = "chip";
  }
  parse_line(s, c.address);
  c.address.line_key = s.key_path("line");

  c.active_low = s.boolean("active_low", false);
  c.bias = bias_from(s.choice("bias", {"as_is", "disable", "pull_up", "pull_down"}, "as_is"));
  if (input) {
    c.edge_events = s.boolean("edge_events", false);
  } else {
    c.drive = drive_from(s.choice("drive", {"push_pull", "open_drain", "open_source"}, "push_pull"));
    c.safe_value = s.boolean("safe_value", false);
    c.charge_pump = s.boolean("charge_pump", false);
    if (s.has("divisor") && !c.charge_pump) {
      s.fail("divisor", "no divisor on a line that is not a charge pump (set charge_pump = true, or remove it)");
    }
    c.divisor = static_cast<std::uint32_t>(s.integer("divisor", 1, 1'000'000, 1));
    if (s.has("enabled_by") && !c.charge_pump) {
      s.fail("enabled_by", "no enabled_by on a line that is not a charge pump (set charge_pump = true, or remove it)");
    }
  }
  return c;
}

// A charge pump's enabled_by: a non-empty array of the names of other digital outputs of this
// driver that are not charge pumps. Resolved once every channel is known, into their indices.
std::vector<std::size_t> parse_enabled_by(const TableReader& s, const std::vector<LineChannel>& channels) {
  constexpr const char* expected =
      "a non-empty array of the names of this driver's digital outputs that must be on for the charge pump "
      "to toggle (the valve enables the relay guards), e.g. enabled_by = [\"valve_enable\"]";
  const toml::node* node = s.table().get("enabled_by");
  if (node == nullptr) s.fail("enabled_by", expected);
  const toml::array* names = node->as_array();
  if (names == nullptr || names->empty()) s.fail("enabled_by", expected);
  std::vector<std::size_t> out;
  for (const toml::node& n : *names) {
    const auto* name = n.as_string();
    if (name == nullptr) s.fail("enabled_by", expected);
    std::size_t j = 0;
    while (j < channels.size() && channels[j].info.name != name->get()) ++j;
    if (j == channels.size()) {
      s.fail("enabled_by", "names of this driver's channels; there is no channel '" + name->get() + "'");
    }
    if (channels[j].info.kind != ChannelKind::digital_output || channels[j].charge_pump) {
      s.fail("enabled_by", "digital outputs that are not charge pumps; '" + name->get() + "' is " +
                               (channels[j].charge_pump ? "a charge pump" : "an input"));
    }
    out.push_back(j);
  }
  return out;
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
  const TableReader s = TableReader::of(table);
  s.reject_unknown_keys({"chip", "channels"});
  const std::string chip = s.string("chip", "a GPIO chip name, /dev path, label or number", "");
  if (s.has("chip") && chip.empty()) s.fail("chip", "a GPIO chip name, /dev path, label or number");

  const std::vector<TableReader> channels = s.tables("channels");
  if (channels.empty()) s.fail("channels", "a non-empty array of tables ([[channels]])");

  GpiodSettings out;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const TableReader& t = channels[i];
    LineChannel c = parse_channel(t, chip);
    for (std::size_t j = 0; j < out.channels.size(); ++j) {
      const LineChannel& o = out.channels[j];
      if (o.info.name == c.info.name) {
        t.fail("name", "a name no other channel has (channels[" + std::to_string(j) + "] is already called \"" +
                           c.info.name + "\")");
      }
      // Only the obvious duplicate is caught here; the same line reached by name and by offset,
      // or through two spellings of one chip, is caught when the lines are resolved.
      if (same_line(o.address, c.address)) {
        t.fail("line", "a line no other channel uses (channels[" + std::to_string(j) + "], " + o.info.name +
                           ", has " + c.address.describe() + " of chip '" + c.address.chip + "')");
      }
    }
    out.channels.push_back(std::move(c));
  }
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (out.channels[i].charge_pump) out.channels[i].enabled_by = parse_enabled_by(channels[i], out.channels);
  }
  return out;
}

}  // namespace hsa::io::gpiod
