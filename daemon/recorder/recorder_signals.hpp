// The recorder row's signals as a table the RT thread can index: each one's name in a capture file,
// its unit, and a plain function that reads it from a row (HSA_RECORDER_SIGNALS, recorder_row.hpp).
// A condition trigger (capture_condition.hpp) names its signal; the operator thread resolves the
// name to an index here once, and the RT thread calls the function through it: no lookup, string
// or allocation per cycle.
#pragma once

#include <cstddef>
#include <string_view>

#include "daemon/recorder/recorder_row.hpp"

namespace hsa::daemon {

struct RecorderSignal {
  const char* name;
  const char* unit;
  double (*read)(const RecorderRow& r) noexcept;
};

inline constexpr RecorderSignal kRecorderSignals[] = {
#define HSA_RECORDER_SIGNAL_ENTRY(name, unit, expr) {name, unit, [](const RecorderRow& r) noexcept -> double { return expr; }},
    HSA_RECORDER_SIGNALS(HSA_RECORDER_SIGNAL_ENTRY)
#undef HSA_RECORDER_SIGNAL_ENTRY
};

inline constexpr std::size_t kRecorderSignalCount = sizeof kRecorderSignals / sizeof kRecorderSignals[0];

// The index of the signal named `name` in kRecorderSignals, or -1.
[[nodiscard]] inline int recorder_signal_index(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kRecorderSignalCount; ++i) {
    if (name == kRecorderSignals[i].name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace hsa::daemon
