#include "drivers/modbus/modbus_settings.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string_view>

#include "drivers/table_reader.hpp"

namespace hsa::io::modbus {
namespace {

WordOrder word_order(const TableReader& s, WordOrder fallback) {
  const std::string order = s.choice("word_order", {"high_first", "low_first"},
                                     fallback == WordOrder::high_first ? "high_first" : "low_first");
  return order == "high_first" ? WordOrder::high_first : WordOrder::low_first;
}

// Seconds in (0, 60): a timeout of a minute or more is a typo for milliseconds, not a setting.
const NumberRange below_a_minute{.min = 0.0, .max = 60.0, .min_exclusive = true, .max_exclusive = true};

bool is_digital(ChannelKind kind) {
  return kind == ChannelKind::digital_input || kind == ChannelKind::digital_output;
}

// The tables a kind may live in, first the natural one.
std::span<const std::string_view> tables_for(ChannelKind kind) {
  static constexpr std::string_view analog_in[] = {"input_register", "holding_register"};
  static constexpr std::string_view analog_out[] = {"holding_register"};
  static constexpr std::string_view digital_in[] = {"discrete_input", "coil"};
  static constexpr std::string_view digital_out[] = {"coil"};
  switch (kind) {
    case ChannelKind::encoder_input:
    case ChannelKind::analog_input: return analog_in;
    case ChannelKind::analog_output: return analog_out;
    case ChannelKind::digital_input: return digital_in;
    case ChannelKind::digital_output: return digital_out;
  }
  return {};
}

Table table_from(std::string_view name) {
  if (name == "coil") return Table::coil;
  if (name == "discrete_input") return Table::discrete_input;
  if (name == "input_register") return Table::input_register;
  return Table::holding_register;
}

ChannelMap parse_channel(const TableReader& s, WordOrder default_order, Duration default_max_age) {
  ChannelMap c;
  c.info.name = s.string("name", "a non-empty string");
  if (c.info.name.empty()) s.fail("name", "a non-empty string");
  const std::string kind = s.choice(
      "kind", {"encoder_input", "analog_input", "analog_output", "digital_input", "digital_output"});
  c.info.kind = *channel_kind_named(kind);  // choice() admitted only kinds
  const bool digital = is_digital(c.info.kind);
  const bool input = is_input(c.info.kind);
  if (s.has("heartbeat") && (input || digital)) {
    s.fail("heartbeat", "no heartbeat on kind \"" + kind +
                            "\" (a heartbeat is an analog_output in table \"holding_register\")");
  }
  if (digital) {
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "table", "address", "max_age_s"}
                                : std::initializer_list<std::string_view>{"name", "kind", "table", "address", "safe_value"});
  } else {
    s.reject_unknown_keys(input ? std::initializer_list<std::string_view>{"name", "kind", "table", "address", "type", "word_order", "scale", "offset", "unit", "max_age_s"}
                                : std::initializer_list<std::string_view>{"name", "kind", "table", "address", "type", "word_order", "scale", "offset", "unit", "safe_value", "heartbeat"});
  }

  const auto allowed = tables_for(c.info.kind);
  std::string expected;
  for (const auto t : allowed) expected += (expected.empty() ? "\"" : " or \"") + std::string(t) + "\"";
  expected += " for kind \"" + kind + "\"";
  const std::string table_name = s.string("table", expected);
  if (std::find(allowed.begin(), allowed.end(), table_name) == allowed.end()) s.fail("table", expected);
  c.table = table_from(table_name);

  c.address = static_cast<int>(s.integer("address", 0, 65535));
  if (!digital) {
    const std::string type = s.choice("type", {"int16", "uint16", "int32", "float32"}, "int16");
    c.type = type == "int16"    ? ValueType::int16
             : type == "uint16" ? ValueType::uint16
             : type == "int32"  ? ValueType::int32
                                : ValueType::float32;
    c.order = word_order(s, default_order);
    c.scale = s.number("scale", NumberRange::any(), 1.0);
    if (c.scale == 0.0) s.fail("scale", "a finite, non-zero number");
    c.offset = s.number("offset", NumberRange::any(), 0.0);
    c.info.unit = s.string("unit", "a unit such as \"m\" or \"Pa\"", "1");
  } else {
    c.info.unit = "1";
  }
  if (c.address + c.width() - 1 > 65535) {
    s.fail("address", "an address whose " + std::to_string(c.width()) + " registers end at or below 65535");
  }
  if (input) {
    c.max_age = s.has("max_age_s") ? s.duration("max_age_s", NumberRange::positive()) : default_max_age;
  } else if (digital) {
    c.safe_value = s.boolean("safe_value", false) ? 1.0 : 0.0;
  } else {
    c.safe_value = s.number("safe_value", NumberRange::any(), 0.0);
    c.heartbeat = s.boolean("heartbeat", false);
    if (c.heartbeat) {
      if (c.table != Table::holding_register) {
        s.fail("heartbeat", "no heartbeat in table \"" + table_name +
                                "\" (a heartbeat is an analog_output in table \"holding_register\")");
      }
      // The counter is written raw: a scaled heartbeat would not count 0, 1, 2, ...
      if (s.has("scale") || s.has("offset")) {
        s.fail("heartbeat", "no scale or offset beside it (a heartbeat counter is written raw)");
      }
    }
  }
  return c;
}

const char* table_name(Table t) {
  switch (t) {
    case Table::coil: return "coil";
    case Table::discrete_input: return "discrete_input";
    case Table::input_register: return "input_register";
    case Table::holding_register: return "holding_register";
  }
  return "?";
}

}  // namespace

std::string LinkSettings::describe() const {
  if (transport == Transport::tcp) return "Modbus TCP " + host + ":" + std::to_string(port);
  return "Modbus RTU " + device;
}

ModbusSettings parse_modbus_settings(const toml::table& table) {
  const TableReader s = TableReader::of(table);
  ModbusSettings out;
  LinkSettings& l = out.link;
  l.transport = s.choice("transport", {"tcp", "rtu"}) == "tcp" ? Transport::tcp : Transport::rtu;
  if (l.transport == Transport::tcp) {
    s.reject_unknown_keys({"transport", "host", "port", "unit_id", "poll_period_s",
                           "response_timeout_s", "max_age_s", "reconnect_min_s", "reconnect_max_s",
                           "output_timeout_s", "word_order", "channels"});
    l.host = s.string("host", "a host name or address", "127.0.0.1");
    if (l.host.empty()) s.fail("host", "a host name or address");
    l.port = static_cast<int>(s.integer("port", 1, 65535, 502));
    l.unit_id = static_cast<int>(s.integer("unit_id", 1, 255, 1));
    // 248..254 are reserved; 255 is the "no serial gateway behind me" unit of Modbus TCP.
    if (l.unit_id > 247 && l.unit_id < 255) s.fail("unit_id", "an integer in [1, 247] or 255");
  } else {
    s.reject_unknown_keys({"transport", "device", "baud", "parity", "data_bits", "stop_bits",
                           "unit_id", "poll_period_s", "response_timeout_s", "max_age_s",
                           "reconnect_min_s", "reconnect_max_s", "output_timeout_s", "word_order", "channels"});
    l.device = s.string("device", "a serial device path (transport \"rtu\")");
    if (l.device.empty()) s.fail("device", "a serial device path");
    l.baud = static_cast<int>(s.integer("baud", 300, 4000000, 19200));
    const std::string parity = s.choice("parity", {"none", "even", "odd"}, "even");
    l.parity = parity == "none" ? 'N' : parity == "even" ? 'E' : 'O';
    l.data_bits = static_cast<int>(s.integer("data_bits", 7, 8, 8));
    l.stop_bits = static_cast<int>(s.integer("stop_bits", 1, 2, 1));
    l.unit_id = static_cast<int>(s.integer("unit_id", 1, 247, 1));
  }
  l.poll_period = s.duration("poll_period_s", NumberRange::positive(), 0.005);
  l.response_timeout = s.duration("response_timeout_s", below_a_minute, 0.05);
  l.reconnect_min = s.duration("reconnect_min_s", NumberRange::positive(), 0.1);
  l.reconnect_max = s.duration("reconnect_max_s", NumberRange::positive(), 2.0);
  if (l.reconnect_max < l.reconnect_min) {
    s.fail("reconnect_max_s", "at least reconnect_min_s (" +
                                  format_setting(std::chrono::duration<double>(l.reconnect_min).count()) + ")");
  }
  l.output_timeout = s.duration("output_timeout_s", below_a_minute, 0.005);
  const Duration max_age = s.duration("max_age_s", NumberRange::positive(), 0.1);
  const WordOrder order = word_order(s, WordOrder::high_first);

  constexpr std::string_view channels_expected = "a non-empty array of tables ([[channels]])";
  const std::vector<TableReader> channels = s.tables("channels");
  if (channels.empty()) s.fail("channels", channels_expected);
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const TableReader& t = channels[i];
    ChannelMap c = parse_channel(t, order, max_age);
    for (const char* reserved :
         {link_up_channel, link_errors_channel, transaction_errors_channel, output_timeouts_channel}) {
      if (c.info.name == reserved) {
        t.fail("name", "a name other than \"" + c.info.name + "\", a status channel the driver declares itself");
      }
    }
    for (std::size_t j = 0; j < out.channels.size(); ++j) {
      const ChannelMap& o = out.channels[j];
      if (o.info.name == c.info.name) {
        t.fail("name", "a name no other channel has (channels[" + std::to_string(j) + "] is already called \"" +
                           c.info.name + "\")");
      }
      if (o.table == c.table && c.address < o.address + o.width() && o.address < c.address + c.width()) {
        t.fail("address", "an address that does not overlap channels[" + std::to_string(j) + "] (" +
                              o.info.name + ") in table " + table_name(c.table));
      }
    }
    out.channels.push_back(std::move(c));
  }
  return out;
}

}  // namespace hsa::io::modbus
