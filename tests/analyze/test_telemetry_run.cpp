// hsa-analyze identify's reader of `hsactl record` CSVs: a run whose samples sit a base tick off
// the loop's grid, or lost one, is taken on the grid from the nearest rows and counted; a run
// missing more than two samples in a row is refused.
#include "tools/hsa_analyze/telemetry_run.hpp"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace hsa::analyze {
namespace {

using control::identification::ClosedLoopRun;
using control::identification::RunRefused;

// One row per seq (base ticks of 100 µs; 10 a loop period); each row's position is its seq, so a
// test can tell which row a grid point was taken from.
std::string csv_of(const std::vector<long>& seqs) {
  std::ostringstream csv;
  ctl::write_telemetry_csv_header(csv);
  for (long seq : seqs) {
    hsa::telemetry_t t{};
    t.seq = seq;
    t.utime = 1'000'000 + seq * 100;
    t.state = hsa::status_t::STATE_ENABLED;
    t.valve_enabled = true;
    t.position_m = static_cast<double>(seq);
    ctl::write_telemetry_csv_row(csv, t);
  }
  return csv.str();
}

// `head`, then regular rows every 10 ticks up to 1000: a run long enough that a few off-grid
// rows stay under the reader's 5 % bound.
std::vector<long> then_regular(std::vector<long> head) {
  for (long s = head.back() + 10; s <= 1000; s += 10) head.push_back(s);
  return head;
}

ClosedLoopRun read(const std::string& text) {
  std::istringstream in(text);
  return read_telemetry_run(in);
}

TEST(TelemetryRun, ARegularRunIsReadAsItIs) {
  const ClosedLoopRun run = read(csv_of({0, 10, 20, 30, 40}));
  EXPECT_DOUBLE_EQ(run.period_s, 1e-3);
  EXPECT_EQ(run.position_m, (std::vector<double>{0, 10, 20, 30, 40}));
  EXPECT_EQ(run.off_grid_samples, 0u);
}

TEST(TelemetryRun, SamplesATickOffTheGridAreTakenAtTheNearestGridPointAndCounted) {
  // The loop ran a tick late at 21 and a tick early at 39.
  const ClosedLoopRun run = read(csv_of(then_regular({0, 10, 21, 30, 39, 50})));
  EXPECT_DOUBLE_EQ(run.period_s, 1e-3);
  ASSERT_EQ(run.position_m.size(), 101u);
  EXPECT_EQ(std::vector<double>(run.position_m.begin(), run.position_m.begin() + 6),
            (std::vector<double>{0, 10, 21, 30, 39, 50}));
  EXPECT_EQ(run.off_grid_samples, 2u);
}

TEST(TelemetryRun, ALostSampleTakesTheNearestRowAndIsCounted) {
  const ClosedLoopRun run = read(csv_of(then_regular({0, 10, 20, 40, 50})));
  ASSERT_EQ(run.position_m.size(), 101u);  // the grid runs on through the gap
  EXPECT_EQ(run.position_m[3], 40.0);    // 30 is as far from 20 as from 40: the later row
  EXPECT_EQ(run.position_m[4], 40.0);
  EXPECT_EQ(run.off_grid_samples, 1u);
}

TEST(TelemetryRun, MoreThanFourLostSamplesInARowAreRefused) {
  std::vector<long> seqs;
  for (long s = 0; s <= 2000; s += 10) seqs.push_back(s);
  std::vector<long> four_lost = seqs, five_lost = seqs;
  four_lost.erase(four_lost.begin() + 50, four_lost.begin() + 54);
  five_lost.erase(five_lost.begin() + 50, five_lost.begin() + 55);
  EXPECT_EQ(read(csv_of(four_lost)).off_grid_samples, 4u);  // still taken, and counted
  try {
    (void)read(csv_of(five_lost));
    ADD_FAILURE() << "five lost samples not refused";
  } catch (const RunRefused& e) {
    EXPECT_NE(std::string(e.what()).find("loop periods apart"), std::string::npos) << e.what();
  }
}

TEST(TelemetryRun, ARunWithMoreThanFivePercentOfItsPeriodsMissedIsRefused) {
  std::vector<long> seqs;
  for (long s = 0; s <= 1000; s += 10) {
    if (s % 160 != 0) seqs.push_back(s);  // every 16th sample lost: 6 %
  }
  try {
    (void)read(csv_of(seqs));
    ADD_FAILURE() << "not refused";
  } catch (const RunRefused& e) {
    EXPECT_NE(std::string(e.what()).find("more than 5 %"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hsa::analyze
