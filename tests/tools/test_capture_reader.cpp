// hsactl's capture tools against captures written by the flight recorder's own writer
// (daemon/recorder/capture_file.hpp): the reader gives back every signal in the recorder's order
// with its unit and its values, the trigger and the strings; the folder listing is newest first
// and lists a file that is no capture as such; the CSV export round-trips every value exactly and
// marks the trigger row; and a file that is no capture, or a CSV that exists, is refused with
// nothing changed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/recorder/capture_file.hpp"
#include "daemon/recorder/capture_folder.hpp"
#include "tools/hsactl/capture_csv.hpp"
#include "tools/hsactl/capture_list.hpp"
#include "tools/hsactl/capture_reader.hpp"
#include "tools/hsactl/capture_scope.hpp"

namespace hsa::ctl {
namespace {

namespace fs = std::filesystem;
using daemon::RecorderRow;

// The recorder's column names and units, in its order, from its own table.
struct Column {
  std::string name, unit;
};
std::vector<Column> recorder_columns() {
  std::vector<Column> out;
#define HSA_TEST_COLUMN(name, unit, expr) out.push_back({name, unit});
  HSA_RECORDER_SIGNALS(HSA_TEST_COLUMN)
#undef HSA_TEST_COLUMN
  out.push_back({"t", "s from the trigger row"});
  out.push_back({"utime_us", "CLOCK_MONOTONIC us (telemetry_t.utime)"});
  return out;
}

// A row's value of the recorder's column `name` (the writer's own expressions).
double value_of(const RecorderRow& r, const std::string& name) {
#define HSA_TEST_VALUE(column, unit, expr) \
  if (name == column) return expr;
  HSA_RECORDER_SIGNALS(HSA_TEST_VALUE)
#undef HSA_TEST_VALUE
  return std::nan("");
}

class CaptureTools : public ::testing::Test {
 protected:
  static constexpr std::size_t kRows = 300;
  static constexpr std::size_t kTrigger = 217;  // 0-based offset of the trigger row in the window

  CaptureTools() : dir_(fs::temp_directory_path() / ("hsactl-captures-" + std::to_string(::getpid()))) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A ring buffer whose window wraps (first is not 0), with values that are not round.
    rows_.resize(kRows + 40);
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      RecorderRow& r = rows_[i];
      r.seq = 1000 + i;
      r.tick = 5000 + i;
      r.t_ns = static_cast<std::int64_t>(r.tick) * 100'000;
      r.setpoint = 0.12 + 1e-7 * static_cast<double>(i);
      r.rod_setpoint_m = 0.1 + 0.01 * std::sin(0.013 * static_cast<double>(i));
      r.position_m = r.rod_setpoint_m - 1e-4 / 3.0;
      r.following_error_m = r.rod_setpoint_m - r.position_m;
      r.command = std::cos(0.02 * static_cast<double>(i)) / 7.0;
      r.pressure_a_pa = 9.81e6 + static_cast<double>(i);
      r.state = 2;
      r.lateness_ns = -static_cast<std::int32_t>(i);
    }
  }
  ~CaptureTools() override { fs::remove_all(dir_); }

  // Writes the window [first, first + kRows) of rows_ (indices into a ring of rows_.size()) with
  // the trigger at first + kTrigger; returns its path in dir_.
  fs::path write(std::uint64_t first, std::int64_t utc_ns, const std::string& axis = "lift") {
    daemon::Capture c;
    c.rows = rows_.data();
    c.capacity = rows_.size();
    c.first = first;
    c.end = first + kRows;
    c.trigger = first + kTrigger;
    c.merged = 2;
    c.why.kind = daemon::TriggerKind::fault;
    c.why.state = daemon::AxisState::fault;
    c.why.fault.reason = daemon::FaultReason::following_error;
    c.why.fault.value = 0.0061;
    c.why.fault.limit = 0.005;
    c.why.tick = c.row(kTrigger).tick;
    c.why.t_ns = c.row(kTrigger).t_ns;
    c.why.kp = 120.0;
    c.why.ki = 30.0;
    reason_ = daemon::capture_reason(c.why);
    const fs::path path = dir_ / daemon::capture_file_name(axis, utc_ns, daemon::capture_reason_word(c.why));
    daemon::write_capture_mat(path.string(), c, {axis, "config text", "a law", 10'000.0, 0});
    written_ = c;
    return path;
  }

  fs::path dir_;
  std::vector<RecorderRow> rows_;
  daemon::Capture written_;
  std::string reason_;
};

TEST_F(CaptureTools, TheReaderGivesBackTheRecordersColumnsUnitsValuesAndTrigger) {
  const fs::path path = write(70, 1'795'000'000'123'000'000);  // wraps: 70 + 300 > 340
  const Capture c = read_capture(path.string());
  const std::vector<Column> columns = recorder_columns();
  ASSERT_EQ(c.signals.size(), columns.size());
  for (std::size_t i = 0; i < columns.size(); ++i) {
    EXPECT_EQ(c.signals[i].name, columns[i].name) << i;
    EXPECT_EQ(c.signals[i].unit, columns[i].unit) << i;
    ASSERT_EQ(c.signals[i].values.size(), kRows) << columns[i].name;
  }
  EXPECT_EQ(c.rows, kRows);
  EXPECT_EQ(c.trigger_index, kTrigger + 1);  // 1-based
  EXPECT_EQ(c.trigger_tick, static_cast<double>(written_.row(kTrigger).tick));
  EXPECT_EQ(c.sample_rate_hz, 10'000.0);
  // (duration_s: TheDurationCountsTheTicksTheExecutiveSkipped; this ring's times wrap with its rows)
  EXPECT_EQ(c.merged_triggers, 2.0);
  EXPECT_EQ(c.axis, "lift");
  EXPECT_EQ(c.reason, reason_);
  EXPECT_NE(c.reason.find("following error"), std::string::npos) << c.reason;
  EXPECT_EQ(c.trigger, "fault");
  EXPECT_EQ(c.trigger_state, "FAULT");
  EXPECT_EQ(c.fault, "following_error");
  EXPECT_EQ(c.law, "a law");
  for (std::size_t k = 0; k < kRows; ++k) {
    const RecorderRow& r = written_.row(k);
    for (const CaptureSignal& s : c.signals) {
      if (s.name == "t") {
        ASSERT_EQ(s.values[k], static_cast<double>(r.t_ns - written_.why.t_ns) * 1e-9) << k;
      } else if (s.name != "utime_us") {
        ASSERT_EQ(s.values[k], value_of(r, s.name)) << s.name << " row " << k;
      }
    }
  }
  EXPECT_EQ(c.signal("t")->values[kTrigger], 0.0);
}

TEST_F(CaptureTools, TheHeaderAloneHasTheRowsButNoValues) {
  const Capture c = read_capture_header(write(0, 1'795'000'000'000'000'000).string());
  EXPECT_EQ(c.rows, kRows);
  EXPECT_EQ(c.trigger_index, kTrigger + 1);
  EXPECT_EQ(c.reason, reason_);
  ASSERT_FALSE(c.signals.empty());
  EXPECT_TRUE(c.signals.front().values.empty());
}

TEST_F(CaptureTools, TheDurationCountsTheTicksTheExecutiveSkipped) {
  EXPECT_NEAR(read_capture_header(write(0, 1'795'000'000'000'000'000).string()).duration_s, 0.03, 1e-12)
      << "300 rows of 100 us";
  for (std::size_t i = 100; i < rows_.size(); ++i) {  // an overrun of 5 base ticks before row 100
    rows_[i].skipped = i == 100 ? 5 : 0;
    rows_[i].tick += 5;
    rows_[i].t_ns += 5 * 100'000;
  }
  const Capture c = read_capture_header(write(0, 1'795'000'000'000'000'000).string());
  EXPECT_EQ(c.rows, kRows);
  EXPECT_NEAR(c.duration_s, 0.0305, 1e-12);  // 300 rows and 5 skipped ticks of 100 us
}

TEST_F(CaptureTools, TheListIsNewestFirstAndNamesAFileThatIsNoCapture) {
  const fs::path older = write(0, 1'795'000'000'000'000'000, "lift");
  const fs::path newer = write(10, 1'795'000'060'500'000'000, "swing");
  std::ofstream(dir_ / "notes.mat") << "not a MAT-file\n";
  std::ofstream(dir_ / "readme.txt") << "left alone\n";
  std::ofstream(dir_ / "lift-20271127T000000.000Z-manual.mat.part") << "being written";
  const std::vector<CaptureListEntry> list = list_captures(dir_.string());
  ASSERT_EQ(list.size(), 3u);  // the .txt and the .part are not captures
  // notes.mat has the file time (now), later than both names' times in 2026.
  EXPECT_EQ(list[0].file, "notes.mat");
  EXPECT_FALSE(list[0].capture.has_value());
  EXPECT_NE(list[0].error.find("not a MAT-file"), std::string::npos) << list[0].error;
  EXPECT_EQ(list[1].file, newer.filename().string());
  EXPECT_EQ(list[2].file, older.filename().string());
  ASSERT_TRUE(list[1].capture.has_value());
  EXPECT_EQ(list[1].capture->axis, "swing");
  EXPECT_EQ(list[1].capture->rows, kRows);
  EXPECT_EQ(list[1].bytes, fs::file_size(newer));
  EXPECT_EQ(list[1].utc, "2026-11-18 11:07:40.500");  // 1795000060.5 s after the epoch (date -u)
  EXPECT_TRUE(list[1].utc_from_name);
}

TEST_F(CaptureTools, TheCsvRoundTripsEveryValueAndMarksTheTriggerRow) {
  const fs::path mat = write(70, 1'795'000'000'000'000'000);
  const fs::path csv = dir_ / "out.csv";
  export_capture_csv(mat.string(), csv.string(), false);
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  std::string expected;
  for (const Column& col : recorder_columns()) expected += col.name + " [" + col.unit + "],";
  EXPECT_EQ(header, expected + "trigger");
  const Capture c = read_capture(mat.string());
  std::size_t k = 0, triggers = 0;
  for (std::string line; std::getline(in, line); ++k) {
    ASSERT_LT(k, kRows);
    std::istringstream fields(line);
    std::string field;
    for (const CaptureSignal& s : c.signals) {
      ASSERT_TRUE(std::getline(fields, field, ','));
      double v = 0;
      ASSERT_EQ(std::from_chars(field.data(), field.data() + field.size(), v).ec, std::errc()) << field;
      ASSERT_EQ(v, s.values[k]) << s.name << " row " << k;
    }
    ASSERT_TRUE(std::getline(fields, field));
    ASSERT_TRUE(field == "0" || field == "1") << field;
    if (field == "1") {
      ++triggers;
      EXPECT_EQ(k, kTrigger);
    }
  }
  EXPECT_EQ(k, kRows);
  EXPECT_EQ(triggers, 1u);
}

TEST_F(CaptureTools, AnExistingCsvIsNotOverwrittenWithoutForce) {
  const fs::path mat = write(0, 1'795'000'000'000'000'000);
  const fs::path csv = dir_ / "out.csv";
  std::ofstream(csv) << "mine\n";
  EXPECT_THROW(export_capture_csv(mat.string(), csv.string(), false), std::runtime_error);
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "mine");
  export_capture_csv(mat.string(), csv.string(), true);
  EXPECT_GT(fs::file_size(csv), kRows * 20);
}

TEST_F(CaptureTools, AFileThatIsNoCaptureIsRefusedAndNoCsvWritten) {
  const fs::path text = dir_ / "notes.mat";
  std::ofstream(text) << "not a MAT-file at all, but long enough to have a header of 128 bytes ............"
                         "................................................................\n";
  const fs::path csv = dir_ / "out.csv";
  try {
    export_capture_csv(text.string(), csv.string(), false);
    FAIL() << "no refusal";
  } catch (const CaptureFileError& e) {
    EXPECT_NE(std::string(e.what()).find(text.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_FALSE(fs::exists(dir_ / "out.csv.part"));
  EXPECT_THROW(read_capture_header((dir_ / "missing.mat").string()), CaptureFileError);
}

TEST_F(CaptureTools, ScopePanelsScaleLengthsToMmAndRefuseAnUnknownSignal) {
  const Capture c = read_capture(write(0, 1'795'000'000'000'000'000).string());
  // mode is 0 (position) throughout: setpoint is a length too.
  const std::vector<ScopePanel> panels = scope_panels(c, kDefaultScopeSignals, true);
  ASSERT_EQ(panels.size(), 3u);
  ASSERT_EQ(panels[0].size(), 3u);
  EXPECT_EQ(panels[0][0].name, "setpoint");
  for (const ScopeTrace& t : panels[0]) EXPECT_EQ((std::pair{t.scale, t.unit}), (std::pair{1e3, std::string("mm")}));
  EXPECT_EQ(panels[2][0].name, "valve_command");
  EXPECT_EQ(panels[2][0].scale, 1.0);
  const std::vector<ScopePanel> bar = scope_panels(c, "pressure_a_pa", false);
  EXPECT_EQ(bar[0][0].unit, "bar");
  std::ostringstream data;
  write_scope_data(data, c, bar);
  double t0 = 0, p0 = 0;
  std::istringstream(data.str()) >> t0 >> p0;
  EXPECT_DOUBLE_EQ(t0, -0.0217);  // row 0: 217 rows of 100 us before the trigger
  EXPECT_DOUBLE_EQ(p0, 98.1);     // 9.81e6 Pa in bar
  try {
    (void)scope_panels(c, "position_m,nonsense", false);
    FAIL() << "no refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'nonsense'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("following_error_m"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hsa::ctl
