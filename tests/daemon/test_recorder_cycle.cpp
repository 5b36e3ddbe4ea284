// The flight recorder inside hsad's RT cycle (DaemonCycle with the recorder hook, on the sim plugin
// in lockstep, hsad's pieces as main.cpp joins them): a fault freezes a capture whose trigger row
// is the cycle the axis entered FAULT, with the whole pre-trigger window at the base rate, the
// rows are the loop's own values, the RT cycles allocate nothing meanwhile, and the capture file
// written from it reads back with libmatio as the rows were.
#include <gtest/gtest.h>

#include <matio.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "daemon/recorder/capture_file.hpp"
#include "daemon/recorder/capture_folder.hpp"
#include "tests/daemon/hsad_pieces.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::daemon {
namespace {

// hsad-sim.toml in lockstep, with pressure A disconnected at `at_s` on the rig's clock.
DaemonConfig sim_config(double at_s) {
  DaemonConfig config = load_config(HSA_SIM_CONFIG);
  toml::table& settings = config.drivers.at(0).settings;
  settings.insert_or_assign("timing", "lockstep");
  settings.insert_or_assign(
      "events", toml::array{toml::table{{"at_s", at_s}, {"sensor", "pressure_a"}, {"fault", "disconnected"}}});
  return config;
}

std::vector<double> read_vector(mat_t* mat, const char* name) {
  matvar_t* v = Mat_VarRead(mat, name);
  if (v == nullptr) return {};
  std::vector<double> out;
  if (v->class_type == MAT_C_DOUBLE && v->rank == 2) {
    const double* d = static_cast<const double*>(v->data);
    out.assign(d, d + v->dims[0] * v->dims[1]);
  }
  Mat_VarFree(v);
  return out;
}

// A text variable (UTF-16 in the file) back as UTF-8; characters beyond the BMP are not needed here.
std::string read_text(mat_t* mat, const char* name) {
  matvar_t* v = Mat_VarRead(mat, name);
  if (v == nullptr) return "<missing>";
  std::string out;
  if (v->class_type == MAT_C_CHAR && v->data_type == MAT_T_UTF16) {
    const auto* units = static_cast<const std::uint16_t*>(v->data);
    for (std::size_t i = 0; i < v->dims[0] * v->dims[1]; ++i) {
      const std::uint16_t u = units[i];
      if (u < 0x80) {
        out += static_cast<char>(u);
      } else if (u < 0x800) {
        out += static_cast<char>(0xC0 | (u >> 6));
        out += static_cast<char>(0x80 | (u & 0x3F));
      } else {
        out += static_cast<char>(0xE0 | (u >> 12));
        out += static_cast<char>(0x80 | ((u >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (u & 0x3F));
      }
    }
  }
  Mat_VarFree(v);
  return out;
}

class RecorderCycle : public ::testing::Test {
 protected:
  RecorderCycle() : config_(sim_config(0.5)), hsad_(config_, 1'000'000'000) {}  // no operator poll: RT work only
  DaemonConfig config_;
  test::HsadPieces hsad_;
};

TEST_F(RecorderCycle, AFaultFreezesTheWindowAroundItsCycleWithoutAnAllocation) {
  ASSERT_EQ(config_.axes[0].recorder.rows, 20'000u);  // the defaults: 2 s at 10 kHz
  ASSERT_EQ(config_.axes[0].recorder.post_rows, 5'000u);
  ASSERT_TRUE(hsad_.run_until(0, AxisState::disabled, 1000));
  const long before = hsa::test::thread_allocations();
  ASSERT_TRUE(hsad_.run_until(0, AxisState::fault, 10'000));
  EXPECT_EQ(hsad_.recorder(0).take(), nullptr);  // still collecting its post-trigger rows
  hsad_.run(4'999);
  EXPECT_EQ(hsad_.recorder(0).take(), nullptr);
  hsad_.run(1);
  EXPECT_EQ(hsa::test::thread_allocations() - before, 0) << "the RT cycles with the recorder allocated";
  const AxisTelemetry& now = hsad_.telemetry(0);

  const Capture* c = hsad_.recorder(0).take();
  ASSERT_NE(c, nullptr);
  const std::size_t k = c->trigger_offset();
  EXPECT_EQ(c->row(k).state, static_cast<std::uint8_t>(AxisState::fault));
  EXPECT_NE(c->row(k - 1).state, static_cast<std::uint8_t>(AxisState::fault));
  EXPECT_EQ(c->row(k).fault_reason, static_cast<std::uint8_t>(FaultReason::sensor_not_ok));
  EXPECT_EQ(c->why.fault.reason, FaultReason::sensor_not_ok);
  EXPECT_EQ(c->why.tick, c->row(k).tick);
  EXPECT_EQ(c->size() - k - 1, 5'000u);
  EXPECT_GT(k, 4'000u);  // the fault came 0.5 s in: that much history before it
  for (std::size_t i = 1; i < c->size(); ++i) {
    ASSERT_EQ(c->row(i).tick, c->row(i - 1).tick + 1) << i;
    ASSERT_EQ(c->row(i).seq, c->row(i - 1).seq + 1) << i;
    ASSERT_EQ(c->row(i).skipped, 0u) << i;  // the pieces' cycles skip nothing
    ASSERT_EQ(c->row(i).t_ns - c->row(i - 1).t_ns, test::HsadPieces::kPeriodNs) << i;
  }
  // The newest row is the cycle just run, as the loop reported it.
  const RecorderRow& last = c->row(c->size() - 1);
  EXPECT_EQ(last.t_ns, now.t_ns);
  EXPECT_EQ(last.position_m, now.position_m);
  EXPECT_EQ(last.pressure_b_pa, now.pressure_b_pa);
  EXPECT_EQ(last.command, now.command);
  EXPECT_EQ(last.state, static_cast<std::uint8_t>(now.state));
  EXPECT_NE(last.position_m, 0.0);  // so that the comparison can fail
  hsad_.recorder(0).release();
}

TEST_F(RecorderCycle, TheCaptureFileReadsBackAsTheRows) {
  ASSERT_TRUE(hsad_.run_until(0, AxisState::fault, 10'000));
  hsad_.run(5'000);
  const Capture* c = hsad_.recorder(0).take();
  ASSERT_NE(c, nullptr);

  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "hsa-test-capture-file";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string path = (folder / "x.mat").string();
  const CaptureContext context{"lift", config_.text, "a law\n", 10'000.0, hsad_.epoch_ns()};
  const std::uint64_t bytes = write_capture_mat(path, *c, context);
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".part"));

  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  EXPECT_EQ(Mat_GetVersion(mat), MAT_FT_MAT5);
  const std::vector<double> position = read_vector(mat, "position_m");
  const std::vector<double> tick = read_vector(mat, "tick");
  const std::vector<double> state = read_vector(mat, "state");
  const std::vector<double> t = read_vector(mat, "t");
  ASSERT_EQ(position.size(), c->size());
  ASSERT_EQ(tick.size(), c->size());
  for (std::size_t i = 0; i < c->size(); ++i) {
    ASSERT_EQ(position[i], c->row(i).position_m) << i;
    ASSERT_EQ(tick[i], static_cast<double>(c->row(i).tick)) << i;
  }
  const std::vector<double> trigger_index = read_vector(mat, "trigger_index");
  ASSERT_EQ(trigger_index.size(), 1u);
  const std::size_t k = static_cast<std::size_t>(trigger_index[0]) - 1;  // 1-based in the file
  EXPECT_EQ(k, c->trigger_offset());
  EXPECT_EQ(state[k], static_cast<double>(AxisState::fault));
  EXPECT_EQ(t[k], 0.0);
  EXPECT_DOUBLE_EQ(t[k - 1], -1e-4);
  EXPECT_EQ(read_text(mat, "axis"), "lift");
  EXPECT_EQ(read_text(mat, "fault"), "sensor_not_ok");
  EXPECT_NE(read_text(mat, "reason").find("pressure A"), std::string::npos) << read_text(mat, "reason");
  EXPECT_EQ(read_text(mat, "configuration"), config_.text);
  EXPECT_NE(read_text(mat, "gains").find("kp = "), std::string::npos);
  Mat_Close(mat);
  hsad_.recorder(0).release();
  std::filesystem::remove_all(folder);
}

// An operator's CAPTURE command from the port: the operator thread checks it against the ring and
// passes it on; the first RT cycle after that takes it, and its row is the trigger, with the
// window asked for. One that does not fit the ring is refused with the reason and changes nothing.
OperatorCommand capture_now(double pre_s, double post_s, std::int64_t counter) {
  OperatorCommand c;
  c.command.kind = CommandKind::capture;
  c.command.capture.action = CaptureAction::now;
  c.command.capture.pre_s = pre_s;
  c.command.capture.post_s = post_s;
  std::snprintf(c.from.operator_id, sizeof c.from.operator_id, "alice");
  c.from.counter = counter;
  return c;
}

TEST_F(RecorderCycle, AnOperatorsCaptureHasTheCycleThatTookItAsItsTrigger) {
  ASSERT_TRUE(hsad_.run_until(0, AxisState::disabled, 1000));
  hsad_.run(3'000);
  hsad_.operators().handle_command(0, capture_now(0.05, 0.02, 1));  // checked, forwarded to the RT thread
  const long before = hsa::test::thread_allocations();
  hsad_.run(1);
  const std::int64_t taken_at_ns = hsad_.telemetry(0).t_ns;  // the cycle that took the command
  hsad_.run(200);
  EXPECT_EQ(hsa::test::thread_allocations() - before, 0);
  const Capture* c = hsad_.recorder(0).take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.kind, TriggerKind::request);
  EXPECT_EQ(capture_reason_word(c->why), "operator");
  EXPECT_EQ(capture_reason(c->why), "operator request");
  const std::size_t k = c->trigger_offset();
  EXPECT_EQ(k, 500u);                   // 0.05 s at 10 kHz before
  EXPECT_EQ(c->size() - k - 1, 200u);   // 0.02 s after
  EXPECT_EQ(c->row(k).tick, c->why.tick);
  EXPECT_EQ(c->row(k).t_ns, taken_at_ns);
  EXPECT_EQ(c->why.t_ns, taken_at_ns);
  hsad_.recorder(0).release();
  hsad_.operators().poll();
  const auto& results = hsad_.operators().command_results(0);
  ASSERT_FALSE(results.empty());
  EXPECT_EQ(results.back().counter, 1);
  EXPECT_TRUE(results.back().accepted) << results.back().reason;

  hsad_.operators().handle_command(0, capture_now(1.8, 0.5, 2));  // 2.3 s: over the 2 s ring
  hsad_.operators().poll();
  hsad_.run(1'000);  // before the fixture's pressure fault (0.5 s in), which would be a trigger of its own
  ASSERT_NE(hsad_.telemetry(0).state, AxisState::fault);
  EXPECT_EQ(hsad_.recorder(0).take(), nullptr) << "a refused capture was taken";
  EXPECT_EQ(hsad_.recorder(0).counts().triggers, 1u);
  const auto& after = hsad_.operators().command_results(0);
  EXPECT_EQ(after.back().counter, 2);
  EXPECT_FALSE(after.back().accepted);
  EXPECT_NE(after.back().reason.find("do not fit the axis's recorder ring of 2 s"), std::string::npos)
      << after.back().reason;
}

TEST_F(RecorderCycle, AConditionCaptureFileSaysItsKindAndCondition) {
  ASSERT_TRUE(hsad_.run_until(0, AxisState::disabled, 1000));
  OperatorCommand c;
  c.command.kind = CommandKind::capture;
  c.command.capture.action = CaptureAction::arm;
  std::snprintf(c.command.capture.signal, sizeof c.command.capture.signal, "t_ns");
  c.command.capture.level = static_cast<double>(hsad_.telemetry(0).t_ns) + 0.05e9;  // 0.05 s from now
  c.command.capture.post_s = 0.01;
  c.command.capture.pre_s = 0.01;
  c.from.counter = 5;
  hsad_.operators().handle_command(0, c);
  hsad_.run(1);
  EXPECT_NE(hsad_.operators().armed_condition(0).find("t_ns above "), std::string::npos)
      << hsad_.operators().armed_condition(0);
  EXPECT_NE(hsad_.operators().armed_condition(0).find("(single, 0.01 s before, 0.01 s after)"), std::string::npos)
      << hsad_.operators().armed_condition(0);
  hsad_.run(1'000);
  const Capture* cap = hsad_.recorder(0).take();
  ASSERT_NE(cap, nullptr);
  const std::size_t k = cap->trigger_offset();
  EXPECT_GT(static_cast<double>(cap->row(k).t_ns), c.command.capture.level);
  EXPECT_LE(static_cast<double>(cap->row(k - 1).t_ns), c.command.capture.level);
  EXPECT_EQ(hsad_.operators().armed_condition(0), "") << "a single-shot condition that fired is still shown";

  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "hsa-test-condition-file";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string path = (folder / "x.mat").string();
  (void)write_capture_mat(path, *cap, {"lift", config_.text, "a law\n", 10'000.0, hsad_.epoch_ns()});
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  EXPECT_EQ(read_text(mat, "trigger"), "condition");
  EXPECT_EQ(read_text(mat, "condition").rfind("t_ns above ", 0), 0u) << read_text(mat, "condition");
  EXPECT_EQ(read_text(mat, "reason").rfind("condition t_ns above ", 0), 0u) << read_text(mat, "reason");
  Mat_Close(mat);
  EXPECT_EQ(capture_file_name("lift", 0, capture_reason_word(cap->why)).rfind("lift-19700101T000000.000Z-t_ns_above_", 0),
            0u);
  hsad_.recorder(0).release();
  std::filesystem::remove_all(folder);
}

TEST(CaptureFile, AnUnwritableFolderThrowsNamingTheFileAndLeavesNothing) {
  CaptureRing ring(10, 2);
  for (int i = 0; i < 5; ++i) {
    ring.slot().tick = static_cast<std::uint64_t>(i);
    if (i == 2) ring.trigger({});
    ring.commit();
  }
  const Capture* c = ring.take();
  ASSERT_NE(c, nullptr);
  const std::string path = "/nonexistent-hsa-folder/x.mat";
  try {
    (void)write_capture_mat(path, *c, {});
    FAIL() << "wrote into a folder that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(CaptureFolder, NamesSayAxisUtcTimeAndReason) {
  // 2026-11-27 05:17:31.250 UTC
  EXPECT_EQ(capture_file_name("lift", 1'795'756'651'250'000'000, "over_pressure"),
            "lift-20261127T051731.250Z-over_pressure.mat");
  EXPECT_EQ(capture_file_name("a", 0, "e-stop!"), "a-19700101T000000.000Z-e_stop_.mat");
}

TEST(CaptureFolder, TheOldestCapturesGoFirstAndOtherFilesStay) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "hsa-test-capture-folder";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const auto make = [&](const std::string& name, std::size_t bytes) {
    std::FILE* f = std::fopen((folder / name).c_str(), "wb");
    const std::string data(bytes, 'x');
    std::fwrite(data.data(), 1, data.size(), f);
    std::fclose(f);
  };
  // Written in an order unlike their times, and an axis name that sorts first on a later capture.
  make("lift-20261127T051731.250Z-over_pressure.mat", 1000);
  make("a-20261127T051700.000Z-estop.mat", 1000);
  make("lift-20261127T051800.000Z-operator.mat", 1000);
  make("notes.txt", 50'000);
  make("lift-20261127T051830.000Z-operator.mat", 1000);

  EXPECT_EQ(prune_captures(folder, {.max_files = 3, .max_bytes = 1'000'000}), 1u);
  EXPECT_FALSE(std::filesystem::exists(folder / "a-20261127T051700.000Z-estop.mat"));
  EXPECT_TRUE(std::filesystem::exists(folder / "lift-20261127T051731.250Z-over_pressure.mat"));
  EXPECT_EQ(prune_captures(folder, {.max_files = 3, .max_bytes = 2000}), 1u);  // bytes bound
  EXPECT_FALSE(std::filesystem::exists(folder / "lift-20261127T051731.250Z-over_pressure.mat"));
  EXPECT_EQ(prune_captures(folder, {.max_files = 3, .max_bytes = 1}), 1u);  // the newest always stays
  EXPECT_TRUE(std::filesystem::exists(folder / "lift-20261127T051830.000Z-operator.mat"));
  EXPECT_TRUE(std::filesystem::exists(folder / "notes.txt"));
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace hsa::daemon
