#include "drivers/channel.hpp"

namespace hsa::io {

std::string_view to_string(ChannelKind kind) {
  switch (kind) {
    case ChannelKind::encoder_input: return "encoder input";
    case ChannelKind::analog_input: return "analog input";
    case ChannelKind::analog_output: return "analog output";
    case ChannelKind::digital_input: return "digital input";
    case ChannelKind::digital_output: return "digital output";
  }
  return "unknown channel kind";
}

std::optional<ChannelKind> channel_kind_named(std::string_view name) {
  if (name == "encoder_input") return ChannelKind::encoder_input;
  if (name == "analog_input") return ChannelKind::analog_input;
  if (name == "analog_output") return ChannelKind::analog_output;
  if (name == "digital_input") return ChannelKind::digital_input;
  if (name == "digital_output") return ChannelKind::digital_output;
  return std::nullopt;
}

}  // namespace hsa::io
