#include "tools/hsactl/observe_commands.hpp"

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "msgs/decode_exact.hpp"
#include "tools/hsactl/interrupt.hpp"
#include "tools/hsactl/status_json.hpp"
#include "tools/hsactl/axis_commands.hpp"
#include "tools/hsactl/driver_report.hpp"
#include "tools/hsactl/telemetry_csv.hpp"
#include "tools/hsactl/value_age.hpp"

namespace hsa::ctl {

using namespace std::chrono_literals;

namespace {

// "kp 85 1/m, ki 460 1/(m s); 2 changes applied, 1 refused (last: ...)"
std::string gains_text(const hsa::status_t& s) {
  char text[160];
  std::snprintf(text, sizeof text, "kp %g 1/m, ki %g 1/(m s); %lld changes applied, %lld refused", s.kp, s.ki,
                static_cast<long long>(s.gain_changes_applied), static_cast<long long>(s.gain_changes_refused));
  return s.gains_refusal.empty() ? std::string(text) : std::string(text) + " (last: " + s.gains_refusal + ")";
}

// A wall-clock time in µs since 1970 as local date and time, "2026-11-25 16:02:07.123".
std::string wall_clock_text(std::int64_t us) {
  const std::time_t seconds = static_cast<std::time_t>(us / 1'000'000);
  std::tm local{};
  localtime_r(&seconds, &local);
  char text[40];
  const std::size_t n = std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &local);
  std::snprintf(text + n, sizeof text - n, ".%03lld", static_cast<long long>(us % 1'000'000 / 1000));
  return text;
}

}  // namespace

int print_gains(LcmSession& session) {
  if (!first_status(session, "gains")) return no_answer_code(session, 2);
  std::printf("%s: %s%s\n", session.axis().c_str(), gains_text(*session.status()).c_str(), session.unverified_tag());
  return 0;
}

int axes(LcmSession& session) {
  // Every axis publishes status at 10 Hz: a second hears each at least once, lost datagrams aside.
  session.run_until(1s, [] { return false; });
  if (session.axes_heard().empty()) {
    std::fprintf(stderr, "hsactl: axes: no axis answered within 1 s (is hsad running, on this LCM URL?)\n");
    return 2;
  }
  // Only an authentic status's state is shown as the axis's.
  bool all_authentic = true;
  for (const auto& [name, heard] : session.axes_heard()) {
    if (heard.authentic) {
      std::printf("%s: %s\n", name.c_str(), state_name(heard.state));
    } else {
      std::printf("%s: (status not verified%s)\n", name.c_str(), session.can_verify() ? "" : ": no key");
      all_authentic = false;
    }
  }
  return all_authentic ? 0 : kExitUnverified;
}

int drivers(LcmSession& session) {
  if (!first_status(session, "drivers")) return no_answer_code(session, 2);
  const hsa::status_t& s = *session.status();
  std::printf("axis %s: %d driver%s%s\n", session.axis().c_str(), s.num_drivers, s.num_drivers == 1 ? "" : "s",
              session.unverified_tag());
  for (const hsa::driver_status_t& d : s.drivers) std::printf("  %s\n", driver_report(d).c_str());
  return 0;
}

int status(LcmSession& session, bool json) {
  if (!first_status(session, "status")) return no_answer_code(session, 2);
  session.run_until(200ms, [&] { return session.telemetry().has_value(); });
  const hsa::status_t& s = *session.status();
  if (json) {
    std::printf("%s\n", status_json(session.axis(), s, session.telemetry() ? &*session.telemetry() : nullptr,
                                    {session.can_verify(), session.verifier().failed()})
                            .dump()
                            .c_str());
    return 0;
  }
  std::printf("axis %s: %s, mode %s%s%s\n", session.axis().c_str(), hsa::ctl::state_name(s.state),
              mode_name(s.mode), s.exciting ? " (exciting: identification run)" : s.holding ? " (holding: setpoints silent)" : "", session.unverified_tag());
  if (session.can_verify()) {
    const std::string failures = session.verifier().failures();
    std::printf("  verified: signed by hsad of system '%s' (instance %016llx) for operator '%s'; %s\n",
                s.system.c_str(), static_cast<unsigned long long>(s.instance), session.operator_id().c_str(),
                failures.empty() ? "0 status messages failed verification" : failures.c_str());
  }
  for (int i = 0; i < s.num_faults; ++i) std::printf("  fault: %s\n", s.fault_reason[i].c_str());
  for (const hsa::driver_status_t& d : s.drivers) std::printf("  driver %s\n", driver_report(d).c_str());
  if (s.sample_utime != 0) {
    std::printf("  rod %.3f mm (%s), setpoint %.3f mm\n", s.position_m * 1e3, age_text(status_position_age(s)).c_str(),
                s.setpoint_m * 1e3);
  }
  if (session.telemetry()) {
    // Telemetry is not authenticated (docs/security.md): shown, and said so.
    const hsa::telemetry_t& t = *session.telemetry();
    std::printf("  telemetry (not authenticated): error %+.3f mm, valve %+.3f, pA %.2f bar, pB %.2f bar\n",
                t.following_error_m * 1e3, t.valve_opening, t.pressure_a_pa / 1e5, t.pressure_b_pa / 1e5);
    std::printf("  inputs (telemetry): %s\n", inputs_text(t).c_str());
  }
  std::printf("  messages: %lld setpoints accepted; rejected %lld non-finite, %lld out of range, %lld undecodable, "
              "%lld unknown\n",
              static_cast<long long>(s.setpoints_accepted), static_cast<long long>(s.rejected_non_finite),
              static_cast<long long>(s.rejected_out_of_range), static_cast<long long>(s.rejected_decode),
              static_cast<long long>(s.rejected_unknown));
  if (s.auth_required) {
    std::printf("  operators: authenticated; refused %lld unknown operator, %lld bad MAC, %lld for another daemon, "
                "%lld replayed, %lld stale stamp\n",
                static_cast<long long>(s.rejected_unknown_operator), static_cast<long long>(s.rejected_bad_mac),
                static_cast<long long>(s.rejected_wrong_daemon), static_cast<long long>(s.rejected_replay),
                static_cast<long long>(s.rejected_stamp));
  }
  if (!s.warning.empty()) std::printf("  WARNING: %s\n", s.warning.c_str());
  if (s.lease_holder.empty()) {
    std::printf("  lease: free (any operator commands the axis); %lld messages refused for a lease\n",
                static_cast<long long>(s.rejected_lease));
  } else {
    std::printf("  lease: held by %s, %.1f s left; %lld messages from others refused\n", s.lease_holder.c_str(),
                s.lease_remaining_s, static_cast<long long>(s.rejected_lease));
  }
  if (s.lease_takeovers > 0) {
    std::printf("  lease taken over %lld time%s; last: by %s from %s at %s\n", static_cast<long long>(s.lease_takeovers),
                s.lease_takeovers == 1 ? "" : "s", s.lease_taken_by.c_str(), s.lease_taken_from.c_str(),
                wall_clock_text(s.lease_taken_at_us).c_str());
  }
  std::printf("  gains: %s\n", gains_text(s).c_str());
  std::printf("  flight recorder: %lld captures written, %lld triggers merged, %lld dropped, %lld write failures; "
              "condition: %s\n",
              static_cast<long long>(s.captures_written), static_cast<long long>(s.capture_triggers_merged),
              static_cast<long long>(s.capture_triggers_dropped), static_cast<long long>(s.capture_write_failures),
              s.capture_condition.empty() ? "none armed" : s.capture_condition.c_str());
  const std::string counted =
      s.rt_allocations < 0 ? std::string("RT allocations and locks not counted (no counting hooks in this hsad)")
                           : "RT allocations " + std::to_string(s.rt_allocations) + ", locks " + std::to_string(s.rt_locks);
  std::printf("  real time: SCHED_FIFO %s, memory %s; overruns %lld, %s, page faults %lld minor / %lld major\n",
              s.sched_fifo ? "granted" : "REFUSED", s.memory_locked ? "locked" : "NOT locked",
              static_cast<long long>(s.rt_overruns), counted.c_str(), static_cast<long long>(s.rt_minor_faults),
              static_cast<long long>(s.rt_major_faults));
  return 0;
}

// A live view, redrawn at 10 Hz, until Ctrl-C or the duration ends.
int watch(LcmSession& session, double duration_s) {
  const auto start = std::chrono::steady_clock::now();
  while (!interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
    session.poll(100ms);
    std::printf("\033[H\033[2J");  // home, clear
    std::printf("hsactl watch — axis %s   (Ctrl-C to quit)\n\n", session.axis().c_str());
    if (!session.telemetry()) {
      std::printf("  waiting for telemetry on HSA/%s/TELEMETRY ...\n", session.axis().c_str());
    } else {
      const hsa::telemetry_t& t = *session.telemetry();
      const double stroke_mm = 304.0;
      std::string bar(51, '.');
      const auto col = [&](double y_m) {
        return static_cast<std::size_t>(std::lround(std::clamp(y_m * 1e3 / stroke_mm, 0.0, 1.0) * 50));
      };
      bar[col(t.setpoint_m)] = '|';
      bar[col(t.position_m)] = '#';
      std::printf("  state      %s%s\n", hsa::ctl::state_name(t.state), t.holding ? " (holding)" : "");
      // The values that come from a stale input (velocity and error from the position) say so where shown.
      const auto mark = [&](int bits) { return (t.stale & bits) != 0 ? "   STALE" : ""; };
      const char* position_mark = mark(hsa::telemetry_t::STALE_POSITION);
      std::printf("  setpoint   %9.3f mm\n  rod        %9.3f mm   [%s]%s\n", t.setpoint_m * 1e3, t.position_m * 1e3,
                  bar.c_str(), position_mark);
      std::printf("  error      %+9.3f mm%s\n  velocity   %+9.2f mm/s%s\n", t.following_error_m * 1e3, position_mark,
                  t.velocity_m_s * 1e3, position_mark);
      std::printf("  valve      %+9.3f opening   current %.3f A   spool %+.3f mm%s   %s\n", t.valve_opening,
                  t.current_ref_a, t.spool_position_m * 1e3, mark(hsa::telemetry_t::STALE_SPOOL),
                  t.valve_enabled ? "enabled" : "DISABLED");
      std::printf("  pressure   A %6.2f bar   B %6.2f bar   load %6.2f bar%s\n", t.pressure_a_pa / 1e5,
                  t.pressure_b_pa / 1e5, t.load_pressure_pa / 1e5,
                  mark(hsa::telemetry_t::STALE_PRESSURE_A | hsa::telemetry_t::STALE_PRESSURE_B));
      std::printf("  inputs     %s%s\n", inputs_text(t).c_str(), t.estop_age_us >= 0 && t.estop ? "; E-STOP PRESSED" : "");
      std::printf("  timing     lateness %6.1f µs (max %.1f)   exec %5.1f µs (max %.1f)   overruns %lld\n",
                  t.lateness_ns / 1e3, t.lateness_max_ns / 1e3, t.exec_time_ns / 1e3, t.exec_time_max_ns / 1e3,
                  static_cast<long long>(t.overruns));
    }
    // Telemetry above is not authenticated (docs/security.md); the faults are from a believed status.
    if (session.status()) {
      for (int i = 0; i < session.status()->num_faults; ++i)
        std::printf("  FAULT      %s%s\n", session.status()->fault_reason[i].c_str(), session.unverified_tag());
    }
    if (session.verifier().failed() > 0) std::printf("  %s\n", session.verifier().failures().c_str());
    std::fflush(stdout);
  }
  return 0;
}

int record(LcmSession& session, const std::string& path, double duration_s) {
  std::ofstream out(path);
  if (!out) {
    std::fprintf(stderr, "hsactl: cannot write '%s'\n", path.c_str());
    return 2;
  }
  hsa::ctl::write_telemetry_csv_header(out);
  std::uint64_t rows = 0;
  session.on_telemetry = [&](const hsa::telemetry_t& t) {
    hsa::ctl::write_telemetry_csv_row(out, t);
    ++rows;
  };
  const auto start = std::chrono::steady_clock::now();
  while (!interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s))
    session.poll(50ms);
  session.on_telemetry = nullptr;
  std::printf("%s: %llu telemetry samples written to %s\n", session.axis().c_str(),
              static_cast<unsigned long long>(rows), path.c_str());
  return rows > 0 ? 0 : 1;
}

int log_to_csv(const std::string& log_path, const std::string& axis, const std::string& csv_path) {
  // An LCM log is a sequence of events, each starting with the sync word 0xEDA1DA01 (big-endian):
  // a file that does not start with it is not a log, whatever lcm::LogFile makes of it.
  std::ifstream raw(log_path, std::ios::binary);
  if (!raw) {
    std::fprintf(stderr, "hsactl: cannot read '%s'\n", log_path.c_str());
    return 2;
  }
  unsigned char sync[4] = {};
  raw.read(reinterpret_cast<char*>(sync), sizeof sync);
  if (raw.gcount() == 0) {
    std::fprintf(stderr, "hsactl: '%s' is empty: not an LCM log file\n", log_path.c_str());
    return 2;
  }
  if (raw.gcount() < 4 || sync[0] != 0xED || sync[1] != 0xA1 || sync[2] != 0xDA || sync[3] != 0x01) {
    std::fprintf(stderr, "hsactl: '%s' is not an LCM log file (lcm-logger writes those)\n", log_path.c_str());
    return 2;
  }
  raw.seekg(0, std::ios::end);
  const std::streamoff size = raw.tellg();
  raw.close();
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    std::fprintf(stderr, "hsactl: cannot read LCM log '%s'\n", log_path.c_str());
    return 2;
  }
  std::ofstream out(csv_path);
  if (!out) {
    std::fprintf(stderr, "hsactl: cannot write '%s'\n", csv_path.c_str());
    return 2;
  }
  hsa::ctl::write_telemetry_csv_header(out);
  const std::string channel = "HSA/" + axis + "/TELEMETRY";
  std::uint64_t rows = 0, undecodable = 0;
  long read_to = 0;  // the end of the last whole event
  for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) {
    read_to = std::ftell(log.getFilePtr());
    if (e->channel != channel) continue;
    hsa::telemetry_t t;
    if (e->datalen < 0 || !hsa::msgs::decode_exact(t, e->data, static_cast<std::size_t>(e->datalen))) {
      ++undecodable;
      continue;
    }
    hsa::ctl::write_telemetry_csv_row(out, t);
    ++rows;
  }
  // The reader stops at the first event it cannot read whole: before the end, the log was cut.
  if (read_to >= 0 && read_to < size) {
    std::fprintf(stderr, "hsactl: '%s' ends in the middle of an event at byte %ld of %lld (truncated?); the events "
                 "before it were converted\n", log_path.c_str(), read_to, static_cast<long long>(size));
  }
  if (rows == 0) {
    std::fprintf(stderr, "hsactl: '%s' holds no telemetry of axis '%s' (%s)%s\n", log_path.c_str(), axis.c_str(),
                 channel.c_str(), undecodable ? ": its messages there do not decode as telemetry_t" : "");
    return 1;
  }
  std::printf("%s: %llu telemetry samples of %s written to %s", log_path.c_str(),
              static_cast<unsigned long long>(rows), channel.c_str(), csv_path.c_str());
  if (undecodable) std::printf(" (%llu undecodable skipped)", static_cast<unsigned long long>(undecodable));
  std::printf("\n");
  return 0;
}

}  // namespace hsa::ctl
