// The flight recorder's settings (docs/flight-recorder.md): per axis, how much of its loop it keeps
// and how much of that follows a trigger; for the daemon, where the captures go and how many.
#pragma once

#include <cstdint>
#include <string>

namespace hsa::daemon {

// [axes.recorder]
struct AxisRecorderConfig {
  double seconds = 2.0;         // the ring: the last `seconds` of the axis's cycles, every base tick
  double post_trigger_s = 0.5;  // of which this much after the trigger; the rest before it
  // Derived from the base rate.
  std::uint64_t rows = 20'000;
  std::uint64_t post_rows = 5'000;
};

// [recorder]
struct RecorderConfig {
  std::string folder;  // "": $STATE_DIRECTORY (systemd's StateDirectory=hsa), else /var/lib/hsa
  std::uint64_t max_files = 100;
  std::uint64_t max_bytes = std::uint64_t{1} << 30;
};

inline constexpr const char* kDefaultRecorderFolder = "/var/lib/hsa";

// The folder captures go to: `configured` when set, else systemd's $STATE_DIRECTORY (its first
// entry), else kDefaultRecorderFolder.
std::string recorder_folder(const RecorderConfig& config);

}  // namespace hsa::daemon
