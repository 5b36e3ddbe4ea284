// `hsactl captures`: the flight recorder's captures in a folder, newest first, each with what its
// file says (axis, reason, rows, duration) read through libmatio, and its size. The time is the
// trigger's UTC time from the file's name (<axis>-<YYYYMMDDTHHMMSS.mmmZ>-<reason>.mat, as
// daemon/recorder/capture_folder.hpp names it; the file holds monotonic times only), else the
// file's modification time. Every *.mat file is listed; one that is no capture is listed as such
// with the reason. `.mat.part` files (being written) are not listed.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tools/hsactl/capture_reader.hpp"

namespace hsa::ctl {

struct CaptureListEntry {
  std::string file;  // the name in the folder
  std::string utc;   // "YYYY-MM-DD HH:MM:SS.mmm"
  bool utc_from_name = false;
  std::uint64_t bytes = 0;
  std::optional<Capture> capture;  // its header; none when unreadable
  std::string error;               // why not, when unreadable
};

// The folder hsad writes captures to when `[recorder] folder` is not set: $STATE_DIRECTORY's first
// entry, else /var/lib/hsa (as daemon/config/recorder_config.hpp).
std::string default_capture_folder();

// The trigger's UTC time "YYYY-MM-DD HH:MM:SS.mmm" from a capture's file name (*from_name true),
// else the file's modification time.
std::string capture_time_utc(const std::filesystem::path& path, bool* from_name);

// Newest first. Throws std::runtime_error naming the folder when it cannot be listed.
std::vector<CaptureListEntry> list_captures(const std::string& folder);

// The table `hsactl captures` prints (a line saying so when there is none).
void print_capture_list(std::FILE* out, const std::string& folder, const std::vector<CaptureListEntry>& entries);

}  // namespace hsa::ctl
