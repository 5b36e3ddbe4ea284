// hsad's metrics as exposition text (daemon/hsad/metrics_text.hpp) and the textfile that carries
// them (metrics_textfile.hpp): every reason's counter from zero, the state as 0/1 gauges, the
// lateness histogram's cumulative buckets, label values from the configuration escaped, the whole
// text accepted by Debian's promtool (`promtool check metrics`), and the file replaced atomically.
#include "daemon/hsad/metrics_text.hpp"
#include "daemon/hsad/metrics_textfile.hpp"
#include "daemon/hsad/prometheus_text.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

MetricsSnapshot two_axes() {
  MetricsSnapshot s;
  s.system = "rig-7";
  s.version = "1.2.3";
  s.start_time_s = 1.7e9;
  s.period_ns = 100'000;
  s.grant.sched_fifo = true;
  s.rt.cycles = 10;
  s.rt.overruns = 2;
  // Lateness: 4 samples at 3 µs, 3 at 7 µs, 2 at 150 µs, 1 at 2 s (the overflow bin).
  s.rt.lateness_histogram[LatencyHistogram::bin_of(3'000)] = 4;
  s.rt.lateness_histogram[LatencyHistogram::bin_of(7'000)] = 3;
  s.rt.lateness_histogram[LatencyHistogram::bin_of(150'000)] = 2;
  s.rt.lateness_histogram[LatencyHistogram::kOverflowBin] = 1;
  s.rt.max_lateness_ns = 2'000'000'000;
  AxisMetrics lift;
  lift.name = "lift";
  lift.state = AxisState::estop;
  lift.latched = FaultReason::estop;
  lift.health.faults[static_cast<std::size_t>(FaultReason::estop)] = 2;
  lift.health.refused[static_cast<std::size_t>(Refusal::estop_active)] = 1;
  lift.health.gains_refused = 4;
  lift.port.rejected[static_cast<std::size_t>(RejectReason::bad_mac)] = 5;
  lift.recorder.written = 6;
  lift.recorder.failed = 1;
  AxisMetrics tilt;
  tilt.name = "tilt";
  tilt.state = AxisState::enabled;
  s.axes = {lift, tilt};
  io::DriverHealth health;
  health.link = io::DriverHealth::Link::not_answering;
  health.counters = {{"link_errors", 9}, {"timeouts", 1}};
  s.drivers = {{"io \"A\"", "modbus", "active", health}};
  return s;
}

TEST(MetricsText, StateAndLatchedFaultAreOneAmongZeros) {
  const std::string t = metrics_text(two_axes());
  EXPECT_THAT(t, HasSubstr("hsa_axis_state{axis=\"lift\",state=\"ESTOP\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_axis_state{axis=\"lift\",state=\"FAULT\"} 0\n"));
  EXPECT_THAT(t, HasSubstr("hsa_axis_state{axis=\"tilt\",state=\"ENABLED\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_axis_fault_latched{axis=\"lift\",reason=\"estop\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_axis_fault_latched{axis=\"tilt\",reason=\"estop\"} 0\n"));
  EXPECT_THAT(t, Not(HasSubstr("reason=\"none\"")));
}

TEST(MetricsText, EveryReasonHasItsCounterFromZero) {
  const std::string t = metrics_text(two_axes());
  EXPECT_THAT(t, HasSubstr("hsa_faults_total{axis=\"lift\",reason=\"estop\"} 2\n"));
  EXPECT_THAT(t, HasSubstr("hsa_faults_total{axis=\"lift\",reason=\"encoder_jump\"} 0\n"));
  EXPECT_THAT(t, HasSubstr("hsa_faults_total{axis=\"tilt\",reason=\"driver_error\"} 0\n"));
  for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
    EXPECT_THAT(t, HasSubstr("hsa_faults_total{axis=\"tilt\",reason=\"" +
                             std::string(to_string(static_cast<FaultReason>(r))) + "\"} 0\n"));
  }
  for (std::size_t r = 1; r < kRefusalCount; ++r) {
    EXPECT_THAT(t, HasSubstr("hsa_commands_refused_total{axis=\"tilt\",reason=\"" +
                             std::string(refusal_id(static_cast<Refusal>(r))) + "\"} 0\n"));
  }
  EXPECT_THAT(t, HasSubstr("hsa_commands_refused_total{axis=\"lift\",reason=\"estop_active\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_messages_rejected_total{axis=\"lift\",reason=\"bad_mac\"} 5\n"));
  EXPECT_THAT(t, HasSubstr("hsa_messages_rejected_total{axis=\"lift\",reason=\"wrong_daemon\"} 0\n"));
  EXPECT_THAT(t, HasSubstr("hsa_gain_changes_refused_total{axis=\"lift\"} 4\n"));
  EXPECT_THAT(t, HasSubstr("hsa_captures_written_total{axis=\"lift\"} 6\n"));
  EXPECT_THAT(t, HasSubstr("hsa_capture_write_failures_total{axis=\"lift\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_overruns_total 2\n"));
}

TEST(MetricsText, RefusalIdsAreDistinctIdentifiers) {
  std::set<std::string_view> seen;
  for (std::size_t r = 0; r < kRefusalCount; ++r) {
    const std::string_view id = refusal_id(static_cast<Refusal>(r));
    EXPECT_NE(id, "invalid") << r;
    EXPECT_TRUE(seen.insert(id).second) << id;
  }
}

TEST(MetricsText, LatenessBucketsAreCumulativeOverTheExecutiveBins) {
  const std::string t = metrics_text(two_axes());
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"5e-06\"} 4\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"1e-05\"} 7\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"0.0001\"} 7\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"0.0002\"} 9\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"1.024\"} 9\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_bucket{le=\"+Inf\"} 10\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_count 10\n"));
  // The bins' lower edges: 4 × 3 µs + 3 × 7 µs + 2 × 150 µs + 1.024 s.
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_seconds_sum " + PrometheusText::format_double(
                                                               4 * 3e-6 + 3 * 7e-6 + 2 * 150e-6 + 1.024) + "\n"));
  EXPECT_THAT(t, HasSubstr("hsa_rt_lateness_max_seconds 2\n"));
}

TEST(MetricsText, EveryBucketBoundIsABinEdge) {
  for (const std::int64_t le : kLatenessBucketsNs) {
    const std::size_t b = LatencyHistogram::bin_of(le);
    EXPECT_EQ(LatencyHistogram::lower_edge_ns(b), le) << le;
  }
}

TEST(MetricsText, DriversCarryLinkStateAndCountersWithTheirNamesEscaped) {
  const std::string t = metrics_text(two_axes());
  EXPECT_THAT(t, HasSubstr("hsa_driver_link{driver=\"io \\\"A\\\"\",plugin=\"modbus\",link=\"not_answering\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_driver_link{driver=\"io \\\"A\\\"\",plugin=\"modbus\",link=\"up\"} 0\n"));
  EXPECT_THAT(t, HasSubstr("hsa_driver_state{driver=\"io \\\"A\\\"\",plugin=\"modbus\",state=\"active\"} 1\n"));
  EXPECT_THAT(t, HasSubstr("hsa_driver_errors_total{driver=\"io \\\"A\\\"\",plugin=\"modbus\",counter=\"link_errors\"} 9\n"));
  EXPECT_THAT(t, HasSubstr("hsa_info{system=\"rig-7\",version=\"1.2.3\"} 1\n"));
}

// A folder of this process's own under the temporary directory (the cases run in parallel).
std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / (name + "-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directory(dir);
  return dir;
}

// Runs promtool on `text`; returns its exit status and output.
std::pair<int, std::string> promtool_check(const std::string& text) {
  const std::filesystem::path dir = scratch("hsa_test_promtool");
  const std::filesystem::path file = dir / "metrics.prom";
  std::ofstream(file) << text;
  const std::string command = std::string(HSA_PROMTOOL) + " check metrics < " + file.string() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  char buf[512];
  while (pipe != nullptr && std::fgets(buf, sizeof buf, pipe) != nullptr) out += buf;
  const int status = pipe == nullptr ? -1 : pclose(pipe);
  std::filesystem::remove_all(dir);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(MetricsText, PromtoolAcceptsTheText) {
  ASSERT_TRUE(std::filesystem::exists(HSA_PROMTOOL)) << "promtool (Debian package prometheus): tools/install-deps";
  const auto [status, out] = promtool_check(metrics_text(two_axes()));
  EXPECT_EQ(status, 0) << out;
  EXPECT_EQ(out, "") << "promtool's lint complains";
  // The check can fail: a counter without _total is a lint error.
  const auto [bad, why] = promtool_check("# HELP x_seconds x\n# TYPE x_seconds counter\nx_seconds 1\n");
  EXPECT_NE(bad, 0);
  EXPECT_THAT(why, HasSubstr("_total"));
}

std::string read(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MetricsTextfile, ReplacesTheFileWholeAndReadableByOthers) {
  const std::filesystem::path dir = scratch("hsa_test_textfile");
  const std::string path = (dir / "hsad.prom").string();
  EXPECT_EQ(MetricsTextfile::write_atomically(path, "a 1\n"), "");
  EXPECT_EQ(MetricsTextfile::write_atomically(path, "b 2\n"), "");
  EXPECT_EQ(read(path), "b 2\n");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  struct stat st{};
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_TRUE(st.st_mode & S_IROTH);  // the node exporter's own user reads it
  std::filesystem::remove_all(dir);
}

TEST(MetricsTextfile, AMissingFolderIsNamedAndLeavesNothing) {
  const std::string path = "/nonexistent-hsa-folder/hsad.prom";
  const std::string error = MetricsTextfile::write_atomically(path, "a 1\n");
  EXPECT_THAT(error, HasSubstr(path + ".tmp"));
  EXPECT_THAT(error, HasSubstr("No such file or directory"));
}

TEST(MetricsTextfile, ItsThreadWritesWhatIsPostedAndStopLeavesRunningZero) {
  const std::filesystem::path dir = scratch("hsa_test_textfile_thread");
  const std::string path = (dir / "hsad.prom").string();
  MetricsTextfile file(path);
  file.start();
  file.post(two_axes());
  for (int i = 0; i < 500 && file.written() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(file.written(), 1u);
  EXPECT_THAT(read(path), HasSubstr("hsa_running 1\n"));
  MetricsSnapshot last = two_axes();
  last.running = false;
  file.stop(last);
  EXPECT_EQ(file.written(), 2u);
  EXPECT_EQ(file.failed(), 0u);
  EXPECT_THAT(read(path), HasSubstr("hsa_running 0\n"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hsa::daemon
