#include "daemon/config/recorder_config_reader.hpp"

#include <cmath>
#include <cstdlib>

namespace hsa::daemon {

// At the 10 kHz base rate 60 s is 600 000 rows of ~130 bytes, twice (capture_ring.hpp): 160 MB of
// locked memory per axis, the most a recorder should take.
constexpr double kMaxRecorderSeconds = 60.0;

std::string recorder_folder(const RecorderConfig& config) {
  if (!config.folder.empty()) return config.folder;
  if (const char* state = std::getenv("STATE_DIRECTORY"); state != nullptr && *state != '\0') {
    const std::string dirs(state);
    return dirs.substr(0, dirs.find(':'));  // systemd lists one per StateDirectory= entry
  }
  return kDefaultRecorderFolder;
}

RecorderConfig parse_recorder(const io::TableReader& root) {
  RecorderConfig c;
  const auto t = root.table("recorder", false, "a table [recorder]");
  if (!t) return c;
  t->reject_unknown_keys({"folder", "max_files", "max_bytes"});
  constexpr std::string_view folder_expected = "the path of a folder for capture files";
  c.folder = t->string("folder", folder_expected, "");
  if (t->has("folder") && c.folder.empty()) t->fail("folder", folder_expected);
  c.max_files = static_cast<std::uint64_t>(t->integer("max_files", 1, 1'000'000, static_cast<std::int64_t>(c.max_files)));
  c.max_bytes = static_cast<std::uint64_t>(
      t->integer("max_bytes", std::int64_t{1} << 20, std::int64_t{1} << 50, static_cast<std::int64_t>(c.max_bytes)));
  return c;
}

AxisRecorderConfig parse_axis_recorder(const io::TableReader& axis, const RealtimeConfig& rt) {
  AxisRecorderConfig c;
  if (const auto t = axis.table("recorder", false, "a table [" + axis.key_path("recorder") + "]")) {
    t->reject_unknown_keys({"seconds", "post_trigger_s"});
    const double tick = rt.base_period_s();
    // At least two rows: the trigger's and one before it.
    c.seconds = t->number("seconds", {.min = 2.0 * tick, .max = kMaxRecorderSeconds}, c.seconds);
    c.post_trigger_s = t->number("post_trigger_s", {.min = 0.0, .max = c.seconds, .max_exclusive = true},
                                 std::min(c.post_trigger_s, c.seconds / 2.0));
  }
  c.rows = static_cast<std::uint64_t>(std::llround(c.seconds * rt.base_rate_hz()));
  c.post_rows = static_cast<std::uint64_t>(std::llround(c.post_trigger_s * rt.base_rate_hz()));
  if (c.post_rows >= c.rows) c.post_rows = c.rows - 1;  // post_trigger_s < seconds, within a tick of it
  return c;
}

}  // namespace hsa::daemon
