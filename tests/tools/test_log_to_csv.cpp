// hsactl record and log2csv: every telemetry field has its column, a file that is not an LCM log
// is named as such with a non-zero exit, and a log cut in the middle of an event is converted up
// to the cut with a warning.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tools/hsactl/observe_commands.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace hsa::ctl {
namespace {

using ::testing::HasSubstr;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  return cells;
}

hsa::telemetry_t sample(std::int64_t seq) {
  hsa::telemetry_t t{};
  t.utime = 1000 + seq;
  t.seq = seq;
  t.position_m = 0.15;
  t.valve_enabled = true;
  t.setpoint_utime = 777;
  t.lateness_max_ns = 4321;
  t.exec_time_max_ns = 1234;
  return t;
}

// The field names of telemetry_t as msgs/telemetry_t.lcm declares them, constants left out.
std::vector<std::string> telemetry_fields() {
  std::ifstream in(HSA_SOURCE_DIR "/msgs/telemetry_t.lcm");
  const std::regex field(R"(^\s*(?:int8_t|int16_t|int32_t|int64_t|float|double|boolean|string|byte)\s+(\w+)\s*(?:\[[^\]]*\]\s*)?;)");
  std::vector<std::string> names;
  std::smatch m;
  for (std::string line; std::getline(in, line);)
    if (std::regex_search(line, m, field)) names.push_back(m[1]);
  return names;
}

// Each case's files in a folder of its own, so that two builds' tests running at once do not share
// files; the folder goes with the case.
class LogToCsv : public ::testing::Test {
 protected:
  LogToCsv() { std::filesystem::create_directories(dir_); }
  ~LogToCsv() override { std::filesystem::remove_all(dir_); }
  std::string temp(const std::string& name) const { return (dir_ / name).string(); }

 private:
  const std::filesystem::path dir_ =
      std::filesystem::temp_directory_path() / ("hsa_test_log_to_csv." + std::to_string(::getpid()));
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A column is named after its field, with the unit appended where the field's name lacks it.
TEST(TelemetryCsv, EveryTelemetryFieldHasAColumnAndTheRowsMatchTheHeader) {
  const std::vector<std::string> fields = telemetry_fields();
  ASSERT_GT(fields.size(), 10u) << "msgs/telemetry_t.lcm not read";
  for (const bool valve_enabled : {true, false}) {
    hsa::telemetry_t t = sample(5);
    t.valve_enabled = valve_enabled;
    std::ostringstream out;
    write_telemetry_csv_header(out);
    write_telemetry_csv_row(out, t);
    std::stringstream lines(out.str());
    std::string header, row;
    std::getline(lines, header);
    std::getline(lines, row);
    const std::vector<std::string> names = split(header), values = split(row);
    EXPECT_EQ(names.size(), fields.size()) << header;
    ASSERT_EQ(values.size(), names.size()) << row;
    for (const std::string& f : fields) {
      EXPECT_EQ(std::count(names.begin(), names.end(), f) + std::count(names.begin(), names.end(), f + "_us"), 1)
          << "telemetry_t." << f << " has no column (or two) in: " << header;
    }
    const auto at = [&](const std::string& name) {
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return values[i];
      ADD_FAILURE() << "no column " << name;
      return std::string();
    };
    EXPECT_EQ(at("valve_enabled"), valve_enabled ? "1" : "0");
    EXPECT_EQ(at("setpoint_utime_us"), "777");
    EXPECT_EQ(at("lateness_max_ns"), "4321");
    EXPECT_EQ(at("exec_time_max_ns"), "1234");
    EXPECT_EQ(at("position_m"), "0.15");
    EXPECT_EQ(at("seq"), "5");
  }
}

TEST_F(LogToCsv, AFileThatIsNotAnLcmLogIsNamedAndRefused) {
  const std::string text = temp("hsa_not_a_log.txt"), empty = temp("hsa_empty.log"), csv = temp("hsa_out.csv");
  std::ofstream(text) << "utime,position\n1,2\n";
  std::ofstream(empty).close();
  testing::internal::CaptureStderr();
  EXPECT_EQ(log_to_csv(text, "lift", csv), 2);
  EXPECT_THAT(testing::internal::GetCapturedStderr(), HasSubstr("'" + text + "' is not an LCM log file"));
  testing::internal::CaptureStderr();
  EXPECT_EQ(log_to_csv(empty, "lift", csv), 2);
  EXPECT_THAT(testing::internal::GetCapturedStderr(), HasSubstr("'" + empty + "' is empty: not an LCM log file"));
}

TEST_F(LogToCsv, ConvertsALogAndSaysWhenItWasCutShort) {
  const std::string path = temp("hsa_telemetry.log"), csv = temp("hsa_telemetry.csv");
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
    for (std::int64_t k = 0; k < 3; ++k) {
      const hsa::telemetry_t t = sample(k);
      std::vector<std::uint8_t> bytes(static_cast<std::size_t>(t.getEncodedSize()));
      ASSERT_GT(t.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
      lcm::LogEvent e{};
      e.eventnum = k;
      e.timestamp = 1000 + k;
      e.channel = k == 1 ? "HSA/other/TELEMETRY" : "HSA/lift/TELEMETRY";
      e.datalen = static_cast<std::int32_t>(bytes.size());
      e.data = bytes.data();
      ASSERT_EQ(log.writeEvent(&e), 0);
    }
  }
  testing::internal::CaptureStdout();
  EXPECT_EQ(log_to_csv(path, "lift", csv), 0);
  EXPECT_THAT(testing::internal::GetCapturedStdout(), HasSubstr("2 telemetry samples of HSA/lift/TELEMETRY"));
  const std::string whole = read_text(csv);
  EXPECT_EQ(std::count(whole.begin(), whole.end(), '\n'), 3);  // header + 2 rows

  // Cut the last event short: the first is still converted, with a warning.
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 10);
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  EXPECT_EQ(log_to_csv(path, "lift", csv), 0);
  (void)testing::internal::GetCapturedStdout();
  EXPECT_THAT(testing::internal::GetCapturedStderr(), HasSubstr("ends in the middle of an event"));
  const std::string converted = read_text(csv);
  EXPECT_EQ(std::count(converted.begin(), converted.end(), '\n'), 2);  // header + 1 row

  testing::internal::CaptureStderr();
  EXPECT_EQ(log_to_csv(path, "nosuchaxis", csv), 1);
  EXPECT_THAT(testing::internal::GetCapturedStderr(), HasSubstr("holds no telemetry of axis 'nosuchaxis'"));
}

}  // namespace
}  // namespace hsa::ctl
