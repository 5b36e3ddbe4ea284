#include "tools/hsactl/telemetry_csv.hpp"

#include <cstdio>
#include <string>

namespace hsa::ctl {
namespace {

// One column: its header and how a sample's field is written. Header and rows come from this one
// list, so they cannot drift apart. Every field of telemetry_t has its column, named after the
// field (with _us where the name has no unit): tests/tools/test_log_to_csv.cpp reads the fields
// from msgs/telemetry_t.lcm and fails on one without. Columns added later go at the end, so that
// scripts reading the earlier ones by position keep working.
struct Column {
  const char* name;
  void (*write)(std::string& out, const hsa::telemetry_t& t);
};

void integer(std::string& out, long long v) { out += std::to_string(v); }
void number(std::string& out, double v, int digits) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  out += text;
}

constexpr Column kColumns[] = {
    {"utime_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.utime); }},
    {"seq", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.seq); }},
    {"state", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.state); }},
    {"holding", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.holding ? 1 : 0); }},
    {"setpoint_m", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.setpoint_m, 9); }},
    {"position_m", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.position_m, 9); }},
    {"velocity_m_s", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.velocity_m_s, 9); }},
    {"following_error_m", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.following_error_m, 9); }},
    {"valve_opening", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.valve_opening, 6); }},
    {"current_ref_a", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.current_ref_a, 6); }},
    {"spool_position_m", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.spool_position_m, 9); }},
    {"pressure_a_pa", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.pressure_a_pa, 8); }},
    {"pressure_b_pa", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.pressure_b_pa, 8); }},
    {"load_pressure_pa", [](std::string& o, const hsa::telemetry_t& t) { number(o, t.load_pressure_pa, 8); }},
    {"lateness_ns", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.lateness_ns); }},
    {"exec_time_ns", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.exec_time_ns); }},
    {"overruns", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.overruns); }},
    {"valve_enabled", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.valve_enabled ? 1 : 0); }},
    {"setpoint_utime_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.setpoint_utime); }},
    {"lateness_max_ns", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.lateness_max_ns); }},
    {"exec_time_max_ns", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.exec_time_max_ns); }},
    {"position_age_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.position_age_us); }},
    {"pressure_a_age_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.pressure_a_age_us); }},
    {"pressure_b_age_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.pressure_b_age_us); }},
    {"spool_age_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.spool_age_us); }},
    {"estop_age_us", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.estop_age_us); }},
    {"estop", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.estop ? 1 : 0); }},
    {"stale", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.stale); }},
    {"exciting", [](std::string& o, const hsa::telemetry_t& t) { integer(o, t.exciting ? 1 : 0); }},
};

}  // namespace

void write_telemetry_csv_header(std::ostream& out) {
  std::string line;
  for (const Column& c : kColumns) line += (line.empty() ? "" : ",") + std::string(c.name);
  out << line << '\n';
}

void write_telemetry_csv_row(std::ostream& out, const hsa::telemetry_t& t) {
  std::string line;
  for (const Column& c : kColumns) {
    if (!line.empty()) line += ',';
    c.write(line, t);
  }
  out << line << '\n';
}

}  // namespace hsa::ctl
