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

}  // namespace hsa::io
