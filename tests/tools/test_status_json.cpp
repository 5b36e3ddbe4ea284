// hsactl status --json: strings from the daemon (fault reasons, refusals, warnings) are escaped,
// however odd, and values that are not finite numbers become null, so every document parses.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tools/hsactl/driver_report.hpp"
#include "tools/hsactl/status_json.hpp"

namespace hsa::ctl {
namespace {

TEST(StatusJson, OddStringsAndNonFiniteNumbersStillParse) {
  hsa::status_t s{};
  s.state = hsa::status_t::STATE_FAULT;
  s.num_faults = 1;
  s.fault_code = {7};
  const std::string reason = "sensor \"pressure_a\" at C:\\rig\ttab\x01 end";
  s.fault_reason = {reason};
  s.gains_refusal = "kp \"1e12\" \\ refused";
  s.kp = std::numeric_limits<double>::quiet_NaN();
  s.ki = 460.0;
  s.lease_remaining_s = std::numeric_limits<double>::infinity();
  hsa::telemetry_t t{};
  t.pressure_a_pa = std::numeric_limits<double>::quiet_NaN();
  t.position_m = 0.15;

  const std::string text = status_json("lift", s, &t, {true, 0}).dump();
  const nlohmann::json parsed = nlohmann::json::parse(text);  // throws on an invalid document
  EXPECT_EQ(parsed["axis"], "lift");
  EXPECT_EQ(parsed["state"], "FAULT");
  EXPECT_EQ(parsed["faults"][0]["code"], 7);
  EXPECT_EQ(parsed["faults"][0]["reason"], reason);
  EXPECT_EQ(parsed["gains_refusal"], s.gains_refusal);
  EXPECT_TRUE(parsed["kp"].is_null());
  EXPECT_EQ(parsed["ki"], 460.0);
  EXPECT_TRUE(parsed["lease_remaining_s"].is_null());
  EXPECT_TRUE(parsed["pressure_a_pa"].is_null());
  EXPECT_EQ(parsed["position_m"], 0.15);
}

TEST(StatusJson, CarriesTheFlightRecordersCountsAndCondition) {
  hsa::status_t s{};
  s.captures_written = 4;
  s.capture_triggers_merged = 2;
  s.capture_triggers_dropped = 1;
  s.capture_write_failures = 3;
  s.capture_condition = "following_error_m above 0.001 (single, 1.5 s before, 0.5 s after)";
  const nlohmann::json parsed = nlohmann::json::parse(status_json("x", s, nullptr, {true, 0}).dump());
  const nlohmann::json& r = parsed["recorder"];
  EXPECT_EQ(r["captures_written"], 4);
  EXPECT_EQ(r["triggers_merged"], 2);
  EXPECT_EQ(r["triggers_dropped"], 1);
  EXPECT_EQ(r["write_failures"], 3);
  EXPECT_EQ(r["condition"], s.capture_condition);
}

TEST(StatusJson, SaysHowFarTheStatusIsTrustedAndWhoTookTheLease) {
  hsa::status_t s{};
  s.system = "rig-a";
  s.instance = 42;
  s.rejected_wrong_daemon = 3;
  s.lease_takeovers = 2;
  s.lease_taken_by = "bob";
  s.lease_taken_from = "alice";
  s.lease_taken_at_us = 1'800'000'000'000'000;
  const nlohmann::json verified = nlohmann::json::parse(status_json("x", s, nullptr, {true, 5}).dump());
  EXPECT_EQ(verified["verified"], true);
  EXPECT_EQ(verified["unverified_status"], 5);
  EXPECT_EQ(verified["system"], "rig-a");
  EXPECT_EQ(verified["instance"], 42);
  EXPECT_EQ(verified["rejected_wrong_daemon"], 3);
  EXPECT_EQ(verified["lease_takeovers"], 2);
  EXPECT_EQ(verified["lease_taken_by"], "bob");
  EXPECT_EQ(verified["lease_taken_from"], "alice");
  EXPECT_EQ(verified["lease_taken_at_us"], 1'800'000'000'000'000);
  EXPECT_EQ(nlohmann::json::parse(status_json("x", s, nullptr, {false, 0}).dump())["verified"], false);
  s.sample_utime = 77;
  s.position_m = 0.2;
  hsa::telemetry_t t{};
  t.position_m = 0.25;  // what a forger on the LAN may have sent
  const nlohmann::json both = nlohmann::json::parse(status_json("x", s, &t, {true, 0}).dump());
  EXPECT_EQ(both["status_position_m"], 0.2);
  EXPECT_EQ(both["status_sample_utime"], 77);
  EXPECT_EQ(both["position_m"], 0.25);
}

// The status's rod with its age at the status's time and hsad's stale mark; telemetry's inputs
// each with theirs, the ones the axis lacks left out.
TEST(StatusJson, ValuesCarryTheirAgeAndStaleMark) {
  hsa::status_t s{};
  s.utime = 5'000'000;
  s.sample_utime = 4'999'000;
  s.position_m = 0.159958;
  s.position_age_us = 2'000'000;
  s.position_stale = true;
  hsa::telemetry_t t{};
  t.position_age_us = 2'000'000;
  t.pressure_a_age_us = 500;
  t.pressure_b_age_us = 500;
  t.spool_age_us = -1;
  t.estop_age_us = -1;
  t.stale = hsa::telemetry_t::STALE_POSITION;
  const nlohmann::json o = nlohmann::json::parse(status_json("x", s, &t, {true, 0}).dump());
  EXPECT_DOUBLE_EQ(o["status_position_age_s"].get<double>(), 2.001);
  EXPECT_EQ(o["status_position_stale"], true);
  EXPECT_EQ(o["inputs"]["position"]["stale"], true);
  EXPECT_DOUBLE_EQ(o["inputs"]["position"]["age_s"].get<double>(), 2.0);
  EXPECT_EQ(o["inputs"]["pressure_a"]["stale"], false);
  EXPECT_DOUBLE_EQ(o["inputs"]["pressure_b"]["age_s"].get<double>(), 0.0005);
  EXPECT_FALSE(o["inputs"].contains("spool"));
  EXPECT_FALSE(o.contains("estop"));  // no e-stop input: no reading to show
}

TEST(StatusJson, DriversCarryTheirLinkCountersAndLastError) {
  hsa::status_t s{};
  hsa::driver_status_t d{};
  d.name = "io";
  d.plugin = "modbus";
  d.state = "active";
  d.link = hsa::driver_status_t::LINK_DOWN;
  d.last_error = "Modbus TCP 127.0.0.1:1502: Connection refused";
  d.num_counters = 1;
  d.counter_name = {"link_errors"};
  d.counter_value = {4};
  s.num_drivers = 1;
  s.drivers = {d};
  const nlohmann::json parsed = nlohmann::json::parse(status_json("x", s, nullptr, {true, 0}).dump());
  ASSERT_EQ(parsed["drivers"].size(), 1u);
  EXPECT_EQ(parsed["drivers"][0]["link"], "down");
  EXPECT_EQ(parsed["drivers"][0]["last_error"], d.last_error);
  EXPECT_EQ(parsed["drivers"][0]["counters"]["link_errors"], 4);
  EXPECT_EQ(driver_report(d),
            "io (modbus): active, LINK DOWN; link_errors 4\n    last error: Modbus TCP 127.0.0.1:1502: Connection refused");
}

TEST(StatusJson, WithoutTelemetryTheTelemetryFieldsAreAbsent) {
  hsa::status_t s{};
  const nlohmann::json parsed = nlohmann::json::parse(status_json("x", s, nullptr, {true, 0}).dump());
  EXPECT_FALSE(parsed.contains("position_m"));
  EXPECT_TRUE(parsed["faults"].empty());
}

}  // namespace
}  // namespace hsa::ctl
