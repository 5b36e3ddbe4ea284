// hsad --stats-json: the document parses, keeps its keys in the documented order, writes the
// histograms' non-empty bins with a null upper edge for the overflow bin, and escapes an axis name.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "daemon/hsad/stats_json.hpp"

namespace hsa::daemon {
namespace {

TEST(StatsJson, HistogramsCountersAndAxesParse) {
  RtStats s;
  s.cycles = 1000;
  s.overruns = 3;
  s.max_lateness_ns = 123'456;
  s.lateness_histogram[2] = 5;
  s.lateness_histogram[LatencyHistogram::kOverflowBin] = 1;
  s.steady = true;
  const RtConfig config;
  RealtimeGrant grant;
  grant.sched_fifo = true;
  grant.memory_locked = true;
  std::vector<AxisRunCounters> axes(1);
  axes[0].name = "odd \"axis\" \\ name";
  axes[0].counters.telemetry_published = 42;

  io::DriverHealth health;
  health.link = io::DriverHealth::Link::down;
  health.last_error = "Modbus TCP 127.0.0.1:1502: Connection refused";
  health.counters = {{"link_errors", 4}, {"transaction_errors", 0}};
  const std::vector<DriverRunHealth> drivers{{"io", "modbus", "active", health}, {"rig", "sim", "active", {}}};

  const nlohmann::ordered_json doc = nlohmann::ordered_json::parse(stats_json(s, config, grant, axes, drivers));
  EXPECT_EQ(doc.begin().key(), "period_ns");
  EXPECT_EQ(doc["period_ns"], 100'000);
  EXPECT_EQ(doc["cycles"], 1000);
  EXPECT_EQ(doc["overruns"], 3);
  EXPECT_EQ(doc["lateness_ns"]["max"], 123'456);
  EXPECT_TRUE(doc["sched_fifo"].get<bool>());
  EXPECT_TRUE(doc["steady"]["reached"].get<bool>());
  const nlohmann::ordered_json& bins = doc["lateness_histogram"];
  ASSERT_EQ(bins.size(), 2u);
  EXPECT_EQ(bins[0][0], LatencyHistogram::lower_edge_ns(2));
  EXPECT_EQ(bins[0][1], LatencyHistogram::upper_edge_ns(2));
  EXPECT_EQ(bins[0][2], 5);
  EXPECT_TRUE(bins[1][1].is_null());
  EXPECT_TRUE(doc["execution_histogram"].empty());
  ASSERT_EQ(doc["axes"].size(), 1u);
  EXPECT_EQ(doc["axes"][0]["name"], axes[0].name);
  EXPECT_EQ(doc["axes"][0]["telemetry_published"], 42);
  ASSERT_EQ(doc["drivers"].size(), 2u);
  EXPECT_EQ(doc["drivers"][0]["name"], "io");
  EXPECT_EQ(doc["drivers"][0]["link"], "down");
  EXPECT_EQ(doc["drivers"][0]["last_error"], health.last_error);
  EXPECT_EQ(doc["drivers"][0]["counters"]["link_errors"], 4);
  EXPECT_EQ(doc["drivers"][1]["link"], "none");
  EXPECT_TRUE(doc["drivers"][1]["counters"].empty());
}

}  // namespace
}  // namespace hsa::daemon
