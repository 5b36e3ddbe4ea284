// Writes a flight recorder capture with the recorder's own writer (daemon/recorder/capture_file.hpp)
// for test_capture_commands.py: 400 rows at 10 kHz, the trigger on row 301 (1-based), a following
// error growing to its limit, axis "lift".
//
//   write_test_capture FOLDER UTC_SECONDS   (prints the file's path)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "daemon/recorder/capture_file.hpp"
#include "daemon/recorder/capture_folder.hpp"

int main(int argc, char** argv) {
  using namespace hsa::daemon;
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s FOLDER UTC_SECONDS\n", argv[0]);
    return 2;
  }
  constexpr std::size_t kRows = 400, kTrigger = 300;
  std::vector<RecorderRow> rows(kRows);
  for (std::size_t i = 0; i < kRows; ++i) {
    RecorderRow& r = rows[i];
    const double t = static_cast<double>(i) * 1e-4;
    r.seq = i;
    r.tick = 10'000 + i;
    r.t_ns = static_cast<std::int64_t>(r.tick) * 100'000;
    r.setpoint = 0.150;
    r.rod_setpoint_m = 0.1 + 0.5 * t;  // a ramp the rod stops following
    r.position_m = i < 200 ? r.rod_setpoint_m - 1e-4 : rows[199].position_m;
    r.following_error_m = r.rod_setpoint_m - r.position_m;
    r.command = i < kTrigger ? std::min(1.0, 0.05 + 40.0 * r.following_error_m) : 0.0;
    r.opening = r.command;
    r.state = i < kTrigger ? 2 : 3;
    r.valve_enabled = i < kTrigger ? 1 : 0;
    r.fault_reason = i < kTrigger ? 0 : static_cast<std::uint8_t>(FaultReason::following_error);
  }
  Capture c;
  c.rows = rows.data();
  c.capacity = kRows;
  c.first = 0;
  c.end = kRows;
  c.trigger = kTrigger;
  c.why.fault.reason = FaultReason::following_error;
  c.why.fault.value = rows[kTrigger].following_error_m;
  c.why.fault.limit = 0.005;
  c.why.tick = rows[kTrigger].tick;
  c.why.t_ns = rows[kTrigger].t_ns;
  const std::string path = std::string(argv[1]) + "/" +
                           capture_file_name("lift", std::atoll(argv[2]) * 1'000'000'000, capture_reason_word(c.why));
  write_capture_mat(path, c, {"lift", "# config\n", "PI", 10'000.0, 0});
  std::printf("%s\n", path.c_str());
  return 0;
}
