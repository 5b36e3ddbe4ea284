// A driver channel: one value the driver exchanges with the hardware, as the driver declares it
// (name, kind, unit), and the slot that carries its raw value through the framework's buffer.
//
// Every slot holds a double, whatever the kind (digital channels store 0 or 1), the way
// ros2_control's state and command interfaces do: one slot type keeps the buffer a plain array
// the framework allocates once, and the driver indexes it by the position of the channel in its
// own declaration.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "drivers/clock.hpp"
#include "drivers/sample_status.hpp"

namespace hsa::io {

enum class ChannelKind : unsigned char {
  encoder_input,
  analog_input,
  analog_output,
  digital_input,
  digital_output,
};

constexpr bool is_input(ChannelKind kind) {
  return kind == ChannelKind::encoder_input || kind == ChannelKind::analog_input ||
         kind == ChannelKind::digital_input;
}

// "encoder input", "analog output", ... for error messages.
std::string_view to_string(ChannelKind kind);

// The kind a plugin's settings name with `kind = "analog_input"` (the enumerator's name), or
// nullopt for any other word.
std::optional<ChannelKind> channel_kind_named(std::string_view name);

struct ChannelInfo {
  std::string name;  // unique within the driver, e.g. "pressure_a"
  ChannelKind kind;
  std::string unit;  // of the raw value, e.g. "Pa", "count", "V"; "1" when dimensionless
};

// One channel's raw value. For an input the driver fills all three fields in read(); for an
// output the framework fills `value` before write() and the driver ignores the other two.
struct ChannelSlot {
  double value = 0.0;
  Timestamp timestamp{};  // when the driver acquired the value
  SampleStatus status = SampleStatus::disconnected;  // nothing read yet
};

}  // namespace hsa::io
