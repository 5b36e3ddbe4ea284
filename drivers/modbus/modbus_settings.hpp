// The modbus plugin's settings, parsed and checked in on_configure into plain structs the bus
// thread and the RT path use without touching TOML again.
//
//   transport = "tcp" | "rtu"                          required
//   tcp:  host = "127.0.0.1"   port = 502               (host: a name or address)
//   rtu:  device = "/dev/ttyUSB0"  baud = 19200  parity = "none"|"even"|"odd"
//         data_bits = 8  stop_bits = 1
//   unit_id = 1                 Modbus slave/unit address (1..247; tcp also 255)
//   poll_period_s = 0.005       the bus thread's cycle
//   response_timeout_s = 0.05   bound on every transaction (modbus_set_response_timeout)
//   max_age_s = 0.1             default staleness limit of input channels
//   reconnect_min_s = 0.1       backoff after a failed connect, doubling up to
//   reconnect_max_s = 2.0
//   output_timeout_s = 0.005    when the RT side has published no output for this long, the bus
//                               thread writes the safe values instead (a stalled daemon)
//   word_order = "high_first" | "low_first"   default for 32-bit channels
//
//   [[channels]]
//   name = "pressure_a"   kind = "analog_input"   table = "input_register"   address = 2
//   type = "float32"      word_order = "low_first"  scale = 1.0  offset = 0.0  unit = "Pa"
//   max_age_s = 0.05      (inputs)      safe_value = 0.0 (outputs; true/false for digital)
//   heartbeat = true      (holding_register outputs only, no scale/offset) the channel's value is
//                         not the slot's but a counter, 0..32767 and around again, that write()
//                         advances on every call: the device sees it stop when the RT side
//                         stops, even while the bus thread keeps polling
//
// kind is one of encoder_input, analog_input, analog_output, digital_input, digital_output, and
// must suit the table: input registers feed analog/encoder inputs, holding registers analog
// outputs (or inputs, read back), discrete inputs digital inputs, coils digital outputs (or
// inputs). Register channels take type (int16, uint16, int32, float32; default int16) and
// scale/offset: value = raw * scale + offset, and raw = (value - offset) / scale on output.
// Addresses are 0-based protocol addresses; channels in one table may not overlap.
//
// Every setting error throws a ConfigError (drivers/table_reader.hpp) naming the place and the key:
//   hsad.toml:31:9: channels[1].table: expected "input_register" or "holding_register" for kind
//   "analog_input", got "coil"
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/channel.hpp"
#include "drivers/clock.hpp"
#include "drivers/modbus/register_codec.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io::modbus {

enum class Table : unsigned char { coil, discrete_input, input_register, holding_register };
enum class Transport : unsigned char { tcp, rtu };

struct LinkSettings {
  Transport transport = Transport::tcp;
  std::string host = "127.0.0.1";
  int port = 502;
  std::string device;
  int baud = 19200;
  char parity = 'E';  // libmodbus's 'N', 'E', 'O'
  int data_bits = 8;
  int stop_bits = 1;
  int unit_id = 1;
  Duration poll_period = std::chrono::milliseconds(5);
  Duration response_timeout = std::chrono::milliseconds(50);
  Duration reconnect_min = std::chrono::milliseconds(100);
  Duration reconnect_max = std::chrono::seconds(2);
  Duration output_timeout = std::chrono::milliseconds(5);

  // "Modbus TCP 127.0.0.1:502" or "Modbus RTU /dev/ttyUSB0", for messages.
  [[nodiscard]] std::string describe() const;
};

struct ChannelMap {
  ChannelInfo info;
  Table table = Table::input_register;
  int address = 0;
  ValueType type = ValueType::int16;  // registers only
  WordOrder order = WordOrder::high_first;
  double scale = 1.0;
  double offset = 0.0;
  double safe_value = 0.0;  // outputs: written while inactive and on deactivate
  Duration max_age{};       // inputs: older than this is stale
  bool heartbeat = false;   // holding_register output carrying write()'s call counter

  [[nodiscard]] int width() const {  // registers or bits the channel occupies
    return table == Table::coil || table == Table::discrete_input ? 1 : register_count(type);
  }
};

struct ModbusSettings {
  LinkSettings link;
  std::vector<ChannelMap> channels;
};

// The names of the status channels the driver always declares after the configured ones.
inline constexpr const char* link_up_channel = "link_up";
inline constexpr const char* link_errors_channel = "link_errors";
inline constexpr const char* transaction_errors_channel = "transaction_errors";
inline constexpr const char* output_timeouts_channel = "output_timeouts";

// Throws ConfigError.
ModbusSettings parse_modbus_settings(const toml::table& table);

}  // namespace hsa::io::modbus
