// The status every input sample carries. It is how sensor and bus faults reach the supervisor:
// the control code never gets a bare number it cannot judge.
#pragma once

#include <string_view>

namespace hsa::io {

enum class SampleStatus : unsigned char {
  ok,
  stale,         // the driver has no fresh value this cycle and hands over the last one
  out_of_range,  // the scaled value is outside the signal's [low_limit, high_limit]
  disconnected,  // no signal at all: broken cable, device not answering, nothing read yet
};

std::string_view to_string(SampleStatus status);

}  // namespace hsa::io
