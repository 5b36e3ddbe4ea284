#include "tools/hsactl/capture_list.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <stdexcept>

namespace hsa::ctl {
namespace {

std::string utc_of_mtime(const std::filesystem::path& path) {
  std::error_code ec;
  const auto when = std::filesystem::last_write_time(path, ec);
  if (ec) return "(no time)";
  const auto sys = std::chrono::file_clock::to_sys(when);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(sys.time_since_epoch()).count();
  const time_t seconds = static_cast<time_t>(ms / 1000);
  tm utc{};
  gmtime_r(&seconds, &utc);
  char text[80];
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d:%02d.%03d", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(ms % 1000));
  return text;
}

std::string human_bytes(std::uint64_t bytes) {
  char text[32];
  if (bytes < 1024) {
    std::snprintf(text, sizeof text, "%llu B", static_cast<unsigned long long>(bytes));
  } else if (bytes < 1024 * 1024) {
    std::snprintf(text, sizeof text, "%.1f KiB", static_cast<double>(bytes) / 1024.0);
  } else {
    std::snprintf(text, sizeof text, "%.2f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  }
  return text;
}

}  // namespace

std::string capture_time_utc(const std::filesystem::path& path, bool* from_name) {
  static const std::regex kName(R"(^[A-Za-z0-9_]+-(\d{4})(\d{2})(\d{2})T(\d{2})(\d{2})(\d{2}\.\d{3})Z-[A-Za-z0-9_]+\.mat$)");
  const std::string name = path.filename().string();
  std::smatch m;
  *from_name = std::regex_match(name, m, kName);
  if (*from_name) return m[1].str() + "-" + m[2].str() + "-" + m[3].str() + " " + m[4].str() + ":" + m[5].str() + ":" + m[6].str();
  return utc_of_mtime(path);
}

std::string default_capture_folder() {
  if (const char* state = std::getenv("STATE_DIRECTORY"); state != nullptr && *state != '\0') {
    const std::string dirs(state);
    return dirs.substr(0, dirs.find(':'));  // systemd lists one per StateDirectory= entry
  }
  return "/var/lib/hsa";
}

std::vector<CaptureListEntry> list_captures(const std::string& folder) {
  std::vector<CaptureListEntry> entries;
  std::error_code listed;
  std::filesystem::directory_iterator it(folder, listed);
  if (listed) throw std::runtime_error(folder + ": cannot list it: " + listed.message());
  for (const auto& entry : it) {
    std::error_code ec;
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec) || entry.path().extension() != ".mat") continue;
    CaptureListEntry e;
    e.file = name;
    e.bytes = entry.file_size(ec);
    if (ec) continue;  // deleted meanwhile (the folder's bound)
    e.utc = capture_time_utc(entry.path(), &e.utc_from_name);
    try {
      e.capture = read_capture_header(entry.path().string());
    } catch (const CaptureFileError& error) {
      const std::string what = error.what();
      const std::string prefix = entry.path().string() + ": ";
      e.error = what.starts_with(prefix) ? what.substr(prefix.size()) : what;
    }
    entries.push_back(std::move(e));
  }
  std::sort(entries.begin(), entries.end(), [](const CaptureListEntry& a, const CaptureListEntry& b) {
    return a.utc != b.utc ? a.utc > b.utc : a.file < b.file;
  });
  return entries;
}

void print_capture_list(std::FILE* out, const std::string& folder, const std::vector<CaptureListEntry>& entries) {
  if (entries.empty()) {
    std::fprintf(out, "no captures in %s\n", folder.c_str());
    return;
  }
  std::size_t width = 4;
  for (const CaptureListEntry& e : entries) width = std::max(width, e.file.size());
  const int w = static_cast<int>(width);
  std::fprintf(out, "%-*s  %-8s  %-23s  %7s  %8s  %9s  %s\n", w, "FILE", "AXIS", "UTC TIME", "ROWS", "DURATION",
               "SIZE", "REASON");
  for (const CaptureListEntry& e : entries) {
    const std::string when = e.utc + (e.utc_from_name ? "" : "*");
    if (!e.capture) {
      std::fprintf(out, "%-*s  %-8s  %-23s  %7s  %8s  %9s  (unreadable: %s)\n", w, e.file.c_str(), "-", when.c_str(),
                   "-", "-", human_bytes(e.bytes).c_str(), e.error.c_str());
      continue;
    }
    const Capture& c = *e.capture;
    char duration[32] = "-";
    if (c.sample_rate_hz > 0) std::snprintf(duration, sizeof duration, "%.3f s", c.duration_s);
    std::string reason = c.reason.empty() ? c.trigger : c.reason;
    if (c.merged_triggers > 0) reason += " (+" + std::to_string(static_cast<long long>(c.merged_triggers)) + " merged)";
    std::fprintf(out, "%-*s  %-8s  %-23s  %7zu  %8s  %9s  %s\n", w, e.file.c_str(),
                 c.axis.empty() ? "?" : c.axis.c_str(), when.c_str(), c.rows, duration, human_bytes(e.bytes).c_str(),
                 reason.c_str());
  }
  if (std::any_of(entries.begin(), entries.end(), [](const CaptureListEntry& e) { return !e.utc_from_name; }))
    std::fprintf(out, "* not named as a capture: the file's modification time\n");
}

}  // namespace hsa::ctl
