#include "tools/hsactl/excite_command.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>

#include "tools/hsactl/axis_commands.hpp"
#include "tools/hsactl/interrupt.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace hsa::ctl {

using namespace std::chrono_literals;

namespace {

std::int64_t send_excite(LcmSession& session, const ExciteOptions& o) {
  return session.send(hsa::command_t::EXCITE, [&](hsa::command_t& msg) {
    msg.excite_at_rod = !o.working_point_m.has_value();
    msg.excite_working_point_m = o.working_point_m.value_or(0.0);
    msg.excite_kind = o.prbs ? hsa::command_t::EXCITE_PRBS : hsa::command_t::EXCITE_PRMS;
    msg.excite_levels = static_cast<std::int16_t>(o.prbs ? 2 : o.levels);
    msg.excite_amplitude_m = o.amplitude_m;
    msg.excite_switching_s = o.switching_s;
    msg.excite_duration_s = o.duration_s;
    msg.excite_seed = o.seed;
    msg.excite_kp = o.kp_per_m;
  });
}

}  // namespace

int excite(LcmSession& session, const ExciteOptions& o) {
  if (!first_status(session, "excite")) return no_answer_code(session, 2);
  if (session.status()->state != hsa::status_t::STATE_ENABLED) {
    std::fprintf(stderr, "hsactl: excite refused: axis '%s' is %s, not ENABLED (hsactl enable first)%s\n",
                 session.axis().c_str(), state_name(session.status()->state), session.unverified_tag());
    print_faults(session);
    return 1;
  }
  std::ofstream out;
  std::uint64_t rows = 0;
  if (!o.record_path.empty()) {
    out.open(o.record_path);
    if (!out) {
      std::fprintf(stderr, "hsactl: cannot write '%s'\n", o.record_path.c_str());
      return 2;
    }
    write_telemetry_csv_header(out);
    // The run's samples only: hsad marks them, so the file is the excitation and nothing else.
    session.on_telemetry = [&](const hsa::telemetry_t& t) {
      if (!t.exciting) return;
      write_telemetry_csv_row(out, t);
      ++rows;
    };
  }
  struct Unhook {
    LcmSession& session;
    ~Unhook() { session.on_telemetry = nullptr; }
  } unhook{session};

  if (const int code = carry_out(session, [&] { return send_excite(session, o); }, "excite"); code != 0) return code;
  // The answer comes after the cycle that started the run: it ends within the duration from here.
  const auto start = std::chrono::steady_clock::now();
  bool seen_running = false;
  const auto bound = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(o.duration_s) + 5s);
  const bool ended = session.run_until(bound, [&] {
    if (interrupted) return true;
    const hsa::status_t& s = *session.status();
    if (s.state != hsa::status_t::STATE_ENABLED) return true;
    if (s.exciting) seen_running = true;
    return !s.exciting && (seen_running || std::chrono::steady_clock::now() - start >= std::chrono::duration<double>(o.duration_s));
  });
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (interrupted) {
    // A MODE command ends the excitation; the axis holds its working point.
    session.send_command(hsa::command_t::MODE, hsa::command_t::MODE_POSITION, 0.0);
    return 130;
  }
  if (session.status()->state != hsa::status_t::STATE_ENABLED) {
    std::fprintf(stderr, "hsactl: excite: the excitation ended after %.1f s of %.1f s:\n", elapsed_s, o.duration_s);
    return not_enabled(session);
  }
  if (!ended) {
    return no_verified_answer(session, "excite: the axis still reports an excitation " +
                                           std::to_string(elapsed_s) + " s after it started",
                              1);
  }
  // A status is sent at every change, so the end is heard within a poll of it (10 ms); sooner than
  // the duration by more than that means something else ended it.
  if (elapsed_s < o.duration_s - 0.5) {
    std::fprintf(stderr, "hsactl: excite: the excitation ended after %.1f s of %.1f s (another command ended it)%s\n",
                 elapsed_s, o.duration_s, session.unverified_tag());
    return 1;
  }
  std::printf("%s: excitation %s +-%.3f mm, switching %.3f s%s, kp %g /m, for %.1f s; holding %.3f mm%s\n",
              session.axis().c_str(), o.prbs ? "PRBS" : "PRMS", o.amplitude_m * 1e3, o.switching_s,
              o.prbs ? "" : (", " + std::to_string(o.levels) + " levels").c_str(), o.kp_per_m, o.duration_s,
              session.status()->setpoint_m * 1e3, session.unverified_tag());
  if (!o.record_path.empty()) {
    std::printf("%s: %llu telemetry samples written to %s\n", session.axis().c_str(),
                static_cast<unsigned long long>(rows), o.record_path.c_str());
    if (rows == 0) return 1;
  }
  return 0;
}

}  // namespace hsa::ctl
