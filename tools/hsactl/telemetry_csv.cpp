#include "tools/hsactl/telemetry_csv.hpp"

#include <cstdio>

namespace hsa::ctl {

void write_telemetry_csv_header(std::ostream& out) {
  out << "utime_us,seq,state,holding,setpoint_m,position_m,velocity_m_s,following_error_m,valve_opening,"
         "current_ref_a,spool_position_m,pressure_a_pa,pressure_b_pa,load_pressure_pa,lateness_ns,exec_time_ns,"
         "overruns\n";
}

void write_telemetry_csv_row(std::ostream& out, const hsa::telemetry_t& t) {
  char line[512];
  std::snprintf(line, sizeof(line),
                "%lld,%lld,%d,%d,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.9g,%.8g,%.8g,%.8g,%d,%d,%lld\n",
                static_cast<long long>(t.utime), static_cast<long long>(t.seq), t.state, t.holding ? 1 : 0,
                t.setpoint_m, t.position_m, t.velocity_m_s, t.following_error_m, t.valve_opening, t.current_ref_a,
                t.spool_position_m, t.pressure_a_pa, t.pressure_b_pa, t.load_pressure_pa, t.lateness_ns,
                t.exec_time_ns, static_cast<long long>(t.overruns));
  out << line;
}

}  // namespace hsa::ctl
