// The flight recorder's folder: how a capture file is named, and the bound on what the folder
// holds (at most max_files captures and max_bytes in all; the oldest go first, the newest always
// stays). Only files named as captures are counted or deleted: anything else in the folder is left
// alone.
//
// Name: <axis>-<UTC time of the trigger, YYYYMMDDTHHMMSS.mmmZ>-<reason>.mat. Axis names have no
// '-', so the time is the second field, and sorting by it is sorting by age.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace hsa::daemon {

struct CaptureFolderLimits {
  std::size_t max_files = 100;
  std::uint64_t max_bytes = std::uint64_t{1} << 30;
};

// `utc_ns`: nanoseconds since the Unix epoch (CLOCK_REALTIME). `reason` is reduced to
// [A-Za-z0-9_].
std::string capture_file_name(const std::string& axis, std::int64_t utc_ns, const std::string& reason);

// Deletes the oldest captures until the folder is within `limits`, keeping the newest. Returns how
// many it deleted. Throws std::filesystem::filesystem_error when the folder cannot be listed.
std::size_t prune_captures(const std::filesystem::path& folder, const CaptureFolderLimits& limits);

}  // namespace hsa::daemon
