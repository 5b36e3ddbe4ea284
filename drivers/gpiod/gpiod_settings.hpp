// The gpiod plugin's settings, parsed and checked in on_configure into plain structs. Parsing
// touches no GPIO: it only says what the table asks for, so it is tested on any machine.
//
//   chip = "gpiochip0"        default chip of every channel (optional when each channel names one)
//
//   [[channels]]
//   name = "estop"            the channel's name, unique
//   kind = "digital_input"    or "digital_output"
//   chip = "gpio-sim.0-node0" the chip: name (gpiochip0), /dev path, label or number, as
//                             gpiod_chip_open_lookup() takes it; default: the top-level chip
//   line = "hsa-estop"        the line: its name (a string) or its offset on the chip (an integer)
//   active_low = false        true: the channel reads/writes 1 while the line is electrically low
//   bias = "as_is"            "as_is", "disable", "pull_up" or "pull_down" (kernel 5.5 and later)
//   edge_events = false       inputs: request both edges and latch every edge between two cycles,
//                             so that a pulse shorter than a cycle is still seen (the e-stop)
//   drive = "push_pull"       outputs: "push_pull", "open_drain" or "open_source"
//   safe_value = false        outputs: the value at configure and after deactivate
//   charge_pump = false       outputs: true makes the line a charge pump (charge_pump.hpp): the
//                             driver toggles it itself in write() while active and enabled, for
//                             an external safety relay, and holds it at safe_value otherwise; the
//                             channel's slot value is ignored (bind no signal to it)
//   enabled_by = ["valve_enable"]
//                             charge pumps only, required: the pump's enable, the names of other
//                             digital outputs of this driver (not charge pumps). The pump toggles
//                             on a write() only while every one of them is written on in that
//                             same write(); otherwise it holds safe_value. hsad writes an axis's
//                             valve enable off in every state but ENABLED, so naming the valve
//                             enables the relay guards stops the wave in the cycle any of those
//                             axes leaves ENABLED (fault, e-stop, disable), and only an enable
//                             after the reset starts it again
//   divisor = 1               charge pumps only: toggle every divisor-th write() (integer >= 1)
//
// Every setting error throws a ConfigError (drivers/table_reader.hpp) naming the place and the key:
//   hsad.toml:12:8: channels[1].line: expected a line name (string) or offset (integer >= 0), got 1.5
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/channel.hpp"
#include "drivers/toml_fwd.hpp"

namespace hsa::io::gpiod {

enum class Bias : unsigned char { as_is, disable, pull_up, pull_down };
enum class Drive : unsigned char { push_pull, open_drain, open_source };

// Where a line is: on which chip, and by name or by offset.
struct LineAddress {
  std::string chip;      // as given: name, path, label or number
  std::string chip_key;  // the key the chip came from: "chip" or "channels[2].chip", for messages
  bool by_name = false;
  std::string name;          // when by_name
  unsigned int offset = 0;   // when !by_name
  std::string line_key;      // "channels[2].line", for messages

  // "line 'hsa-estop'" or "line 3", for messages.
  [[nodiscard]] std::string describe() const;
};

struct LineChannel {
  ChannelInfo info;  // kind digital_input or digital_output, unit "1"
  LineAddress address;
  bool active_low = false;
  Bias bias = Bias::as_is;
  bool edge_events = false;  // inputs only
  Drive drive = Drive::push_pull;  // outputs only
  bool safe_value = false;   // outputs only
  bool charge_pump = false;  // outputs only
  std::uint32_t divisor = 1; // charge pumps only
  // Charge pumps only: the indices (into GpiodSettings::channels) of the outputs that enable it.
  std::vector<std::size_t> enabled_by;
};

struct GpiodSettings {
  std::vector<LineChannel> channels;
};

// Throws ConfigError.
GpiodSettings parse_gpiod_settings(const toml::table& table);

}  // namespace hsa::io::gpiod
