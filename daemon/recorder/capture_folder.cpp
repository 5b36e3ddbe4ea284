#include "daemon/recorder/capture_folder.hpp"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <regex>
#include <vector>

namespace hsa::daemon {

std::string capture_file_name(const std::string& axis, std::int64_t utc_ns, const std::string& reason) {
  const time_t seconds = static_cast<time_t>(utc_ns / 1'000'000'000);
  const int ms = static_cast<int>((utc_ns % 1'000'000'000) / 1'000'000);
  tm utc{};
  gmtime_r(&seconds, &utc);
  char when[80];  // room for any int the compiler cannot rule out
  std::snprintf(when, sizeof when, "%04d%02d%02dT%02d%02d%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, ms);
  std::string word;
  for (const char ch : reason) {
    const bool plain = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_';
    word += plain ? ch : '_';
  }
  return axis + "-" + when + "-" + (word.empty() ? "capture" : word) + ".mat";
}

std::size_t prune_captures(const std::filesystem::path& folder, const CaptureFolderLimits& limits) {
  static const std::regex kCapture(R"(^[A-Za-z0-9_]+-(\d{8}T\d{6}\.\d{3}Z)-[A-Za-z0-9_]+\.mat$)");
  struct File {
    std::string when, name;
    std::uint64_t bytes;
  };
  std::vector<File> files;
  std::uint64_t total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    std::error_code ec;
    if (!entry.is_regular_file(ec) || !std::regex_match(name, m, kCapture)) continue;
    const std::uint64_t bytes = entry.file_size(ec);
    if (ec) continue;  // deleted meanwhile
    files.push_back({m[1].str(), name, bytes});
    total += bytes;
  }
  std::sort(files.begin(), files.end(),
            [](const File& a, const File& b) { return a.when != b.when ? a.when < b.when : a.name < b.name; });
  std::size_t deleted = 0;
  std::size_t count = files.size();
  for (const File& f : files) {
    if (count <= 1 || (count <= limits.max_files && total <= limits.max_bytes)) break;
    std::error_code ec;
    if (std::filesystem::remove(folder / f.name, ec)) ++deleted;
    --count;
    total -= f.bytes;
  }
  return deleted;
}

}  // namespace hsa::daemon
