// hsactl: the operator's command line for hsad, over LCM.
//
//   hsactl [--axis NAME] [--key FILE] enable|disable|reset|acquire [--force]|release|mode position|open-loop|
//          open OPENING|move POS|step AMPL|sine AMPL FREQ|gains KP KI|status [--json]|watch|record FILE.csv|
//          log2csv LOG FILE.csv
//   hsactl keygen NAME [--dir DIR]
//
// Setpoints and commands are signed with the operator's key (`--key FILE`, or the file named by
// HSA_KEY): hsad obeys only operators whose key it holds (msgs/README.md, Authentication). `keygen`
// makes a key, NAME.key with mode 0600, for the operator NAME; hsad's copy goes in its key_dir.
// `acquire` takes the axis's lease: until `release` (or the lease's timeout) only this operator
// commands it, except that anyone's DISABLE is obeyed. Each command waits for hsad's
// acknowledgement of its counter, sends it again if none comes, and prints hsad's reason if it
// refuses.
//
// `gains` sets the cylinder PI's kp (1/m) and ki (1/(m s)) while the axis runs (command_t.GAINS);
// the daemon refuses gains outside the axis's max_kp / max_ki, and hsactl then prints its reason.
//
// `mode` selects the axis's control mode (command_t.MODE): closed-loop position, or open loop, where
// the valve opening is commanded directly. `open` streams an opening in open-loop mode (switching
// to it first) for a while, then commands opening 0: the daemon treats the opening like a
// setpoint, so it falls back to 0 by itself once the stream stops for longer than its setpoint
// timeout.
//
// Positions are given and shown in mm, pressures in bar; the wire carries SI units. Commands that
// change the axis wait for its status to confirm and exit non-zero (with the daemon's reason) when
// it does not, so scripts can rely on the exit code. Every wait is bounded.
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <thread>

#include "msgs/auth/operator_key.hpp"
#include "msgs/decode_exact.hpp"
#include "tools/hsactl/lcm_session.hpp"
#include "tools/hsactl/status_json.hpp"
#include "tools/hsactl/telemetry_csv.hpp"

namespace {

using namespace std::chrono_literals;
using hsa::ctl::LcmSession;
using hsa::ctl::mode_name;
using hsa::ctl::status_json;

std::atomic<bool> g_interrupted{false};
void on_signal(int) { g_interrupted = true; }

void print_faults(const hsa::status_t& s) {
  for (int i = 0; i < s.num_faults; ++i) std::fprintf(stderr, "  fault: %s\n", s.fault_reason[i].c_str());
}

// Why the daemon refused this session's messages between two statuses, or "" when nothing says
// it did. A refusal is counted, never answered, so the counters are the only trace; they are the
// axis's, not this session's, which is why they are read only when no acknowledgement came.
std::string refusal(const LcmSession& session, const hsa::status_t& before, const hsa::status_t& now) {
  if (now.auth_required && !session.signing()) {
    return "hsad requires signed commands: give --key FILE (or set HSA_KEY) with an operator key it holds";
  }
  const std::string who = "operator '" + session.operator_id() + "'";
  if (now.rejected_unknown_operator > before.rejected_unknown_operator) return "hsad holds no key for " + who;
  if (now.rejected_bad_mac > before.rejected_bad_mac) {
    return "hsad's key for " + who + " is not this one (MAC refused)";
  }
  if (now.rejected_stamp > before.rejected_stamp) {
    return "the message's time stamp is outside hsad's window: are this host's and hsad's clocks set?";
  }
  if (now.rejected_replay > before.rejected_replay) {
    return "counter refused as a replay: another hsactl of " + who + " is sending to this axis";
  }
  if (now.rejected_lease > before.rejected_lease && !now.lease_holder.empty() &&
      now.lease_holder != session.operator_id()) {
    return "axis '" + session.axis() + "' is held by operator '" + now.lease_holder +
           "' (hsactl acquire --force takes it over; hsad logs that)";
  }
  if (now.rejected_non_finite > before.rejected_non_finite) return "a value is not a finite number";
  if (now.rejected_out_of_range > before.rejected_out_of_range) return "a value is out of its range";
  if (now.rejected_unknown > before.rejected_unknown) return "hsad does not know this command";
  return "";
}

// Waits for a first status, the baseline a refusal is judged against; false (and says so) when
// none comes.
bool first_status(LcmSession& session, const char* verb) {
  if (session.run_until(3s, [&] { return session.status().has_value(); })) return true;
  std::fprintf(stderr, "hsactl: %s: no status from axis '%s' within 3 s (is hsad running?)\n", verb,
               session.axis().c_str());
  return false;
}

// Sends a command (by `send`, which returns its counter) until hsad acknowledges it in its status:
// a datagram can be lost, so without an acknowledgement or a refusal within 0.5 s it sends it
// again (a new message with a new counter), three times in all. True when acknowledged; otherwise
// it has printed hsad's reason, or that nothing answered.
bool deliver(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb) {
  if (!first_status(session, verb)) return false;
  const hsa::status_t before = *session.status();
  for (int attempt = 0; attempt < 3; ++attempt) {
    const std::int64_t counter = send();
    std::string why;
    const bool answered = session.run_until(500ms, [&] {
      const auto ack = session.acknowledged(*session.status());
      if (ack && *ack >= counter) return true;
      why = refusal(session, before, *session.status());
      return !why.empty();
    });
    if (answered && why.empty()) return true;
    if (answered) {
      std::fprintf(stderr, "hsactl: %s refused: %s\n", verb, why.c_str());
      return false;
    }
  }
  std::fprintf(stderr, "hsactl: %s: axis '%s' did not acknowledge it, sent 3 times in 1.5 s\n", verb,
               session.axis().c_str());
  return false;
}

// Sends a command and waits until the status reports `want` (or a state that rules it out).
int command_and_confirm(LcmSession& session, std::int8_t command, std::int8_t want, const char* verb) {
  if (!deliver(session, [&] { return session.send_command(command); }, verb)) return 1;
  const bool confirmed = session.run_until(3s, [&] { return session.status()->state == want; });
  if (confirmed) {
    std::printf("%s: %s\n", session.axis().c_str(), hsa::ctl::state_name(want));
    return 0;
  }
  std::fprintf(stderr, "hsactl: %s refused: axis '%s' is %s\n", verb, session.axis().c_str(),
               hsa::ctl::state_name(session.status()->state));
  print_faults(*session.status());
  return 1;
}

// ACQUIRE (with --force: from its holder) or RELEASE the axis's lease.
int lease_command(LcmSession& session, bool acquire, bool force) {
  const char* verb = acquire ? "acquire" : "release";
  const std::int8_t command = acquire ? hsa::command_t::ACQUIRE : hsa::command_t::RELEASE;
  if (!deliver(session, [&] { return session.send_command(command, 0, 0.0, force); }, verb)) return 1;
  const hsa::status_t& s = *session.status();
  if (acquire) {
    std::printf("%s: held by %s (lease %.0f s, renewed by each of its commands)\n", session.axis().c_str(),
                s.lease_holder.c_str(), s.lease_remaining_s);
  } else {
    std::printf("%s: released\n", session.axis().c_str());
  }
  return 0;
}

// Sends a MODE command and waits until the status reports the mode.
int mode_and_confirm(LcmSession& session, std::int8_t mode) {
  if (!deliver(session, [&] { return session.send_command(hsa::command_t::MODE, mode, 0.0); }, "mode")) return 1;
  if (session.run_until(3s, [&] { return session.status()->mode == mode; })) {
    std::printf("%s: mode %s\n", session.axis().c_str(), mode_name(mode));
    return 0;
  }
  std::fprintf(stderr, "hsactl: mode %s not confirmed: axis '%s' is %s in mode %s\n", mode_name(mode),
               session.axis().c_str(), hsa::ctl::state_name(session.status()->state),
               mode_name(session.status()->mode));
  print_faults(*session.status());
  return 1;
}

// Sends GAINS and waits until the status counts it applied or refused by the axis (with its
// reason); the daemon's message checks (NaN, kp <= 0, ki < 0) refuse it before that.
int gains_and_confirm(LcmSession& session, double kp, double ki) {
  if (!first_status(session, "gains")) return 2;
  const hsa::status_t before = *session.status();
  if (!deliver(session, [&] { return session.send_gains(kp, ki); }, "gains")) return 1;
  const bool answered = session.run_until(3s, [&] {
    const hsa::status_t& s = *session.status();
    return s.gain_changes_applied > before.gain_changes_applied ||
           s.gain_changes_refused > before.gain_changes_refused;
  });
  const hsa::status_t& s = *session.status();
  if (answered && s.gain_changes_applied > before.gain_changes_applied) {
    std::printf("%s: gains kp %g 1/m, ki %g 1/(m s)\n", session.axis().c_str(), s.kp, s.ki);
    return 0;
  }
  if (!answered) {
    std::fprintf(stderr, "hsactl: gains not confirmed by axis '%s' within 3 s\n", session.axis().c_str());
  } else {
    std::fprintf(stderr, "hsactl: gains refused: %s\n", s.gains_refusal.c_str());
  }
  return 1;
}

// Open loop: streams `opening` at 20 Hz for `duration_s` (well inside the daemon's setpoint
// timeout), then commands opening 0. Fails when the axis is not ENABLED or leaves it.
int open_valve(LcmSession& session, double opening, double duration_s) {
  const double start_m = session.telemetry()->position_m;
  const auto start = std::chrono::steady_clock::now();
  int code = 0;
  while (!g_interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
    session.send_command(hsa::command_t::MODE, hsa::command_t::MODE_VALVE_OPENING, opening);
    session.poll(50ms);
    const hsa::telemetry_t& t = *session.telemetry();
    if (t.state != hsa::status_t::STATE_ENABLED) {
      std::fprintf(stderr, "hsactl: axis '%s' is %s, not ENABLED\n", session.axis().c_str(),
                   hsa::ctl::state_name(t.state));
      if (session.status()) print_faults(*session.status());
      code = 1;
      break;
    }
  }
  session.send_command(hsa::command_t::MODE, hsa::command_t::MODE_VALVE_OPENING, 0.0);
  session.poll(50ms);
  const double end_m = session.telemetry()->position_m;
  std::printf("%s: opening %+.3f for %.1f s: rod %.3f mm -> %.3f mm\n", session.axis().c_str(), opening,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), start_m * 1e3,
              end_m * 1e3);
  return g_interrupted ? 130 : code;
}

bool wait_for_telemetry(LcmSession& session) {
  if (session.run_until(3s, [&] { return session.telemetry().has_value(); })) return true;
  std::fprintf(stderr, "hsactl: no telemetry from axis '%s' within 3 s (is hsad running?)\n",
               session.axis().c_str());
  return false;
}

// Streams the target at 100 Hz (the daemon holds position when setpoints stop) until the rod has
// stayed within `tolerance` of it for 0.2 s, or the timeout passes.
int move_to(LcmSession& session, double target_m, double tolerance_m, double timeout_s) {
  const hsa::status_t before = *session.status();
  const auto start = std::chrono::steady_clock::now();
  auto inside_since = start;
  bool inside = false;
  while (!g_interrupted) {
    session.send_setpoint(target_m);
    session.poll(10ms);
    const auto now = std::chrono::steady_clock::now();
    const hsa::telemetry_t& t = *session.telemetry();
    if (t.state != hsa::status_t::STATE_ENABLED) {
      std::fprintf(stderr, "hsactl: axis '%s' is %s, not ENABLED\n", session.axis().c_str(),
                   hsa::ctl::state_name(t.state));
      if (session.status()) print_faults(*session.status());
      return 1;
    }
    const bool near = std::abs(t.position_m - target_m) <= tolerance_m;
    if (near && !inside) inside_since = now;
    inside = near;
    if (inside && now - inside_since >= 200ms) {
      std::printf("%s: at %.3f mm (target %.3f mm)\n", session.axis().c_str(), t.position_m * 1e3, target_m * 1e3);
      return 0;
    }
    if (now - start > std::chrono::duration<double>(timeout_s)) {
      std::fprintf(stderr, "hsactl: move timed out after %.1f s at %.3f mm (target %.3f mm)\n", timeout_s,
                   t.position_m * 1e3, target_m * 1e3);
      // The counters are the axis's, not this session's: a hint, given only when it explains.
      const std::string why = refusal(session, before, *session.status());
      if (!why.empty()) std::fprintf(stderr, "  (hsad refused messages meanwhile: %s)\n", why.c_str());
      return 1;
    }
  }
  return 130;
}

int sine(LcmSession& session, double amplitude_m, double frequency_hz, double duration_s) {
  const double centre = session.telemetry()->position_m;
  double worst = 0.0;
  session.on_telemetry = [&](const hsa::telemetry_t& t) {
    if (t.state == hsa::status_t::STATE_ENABLED) worst = std::max(worst, std::abs(t.following_error_m));
  };
  const auto start = std::chrono::steady_clock::now();
  for (long k = 0; !g_interrupted; ++k) {
    const double t = k * 1e-3;  // 1 kHz setpoint stream
    if (t > duration_s) break;
    session.send_setpoint(centre + amplitude_m * std::sin(2.0 * std::numbers::pi * frequency_hz * t));
    session.poll(0ms);
    std::this_thread::sleep_until(start + std::chrono::duration<double>(t + 1e-3));
  }
  session.on_telemetry = nullptr;
  std::printf("%s: sine %.3f mm at %.3f Hz for %.1f s around %.3f mm; max |following error| %.3f mm\n",
              session.axis().c_str(), amplitude_m * 1e3, frequency_hz, duration_s, centre * 1e3, worst * 1e3);
  return g_interrupted ? 130 : 0;
}

int status(LcmSession& session, bool json) {
  if (!session.run_until(3s, [&] { return session.status().has_value(); })) {
    std::fprintf(stderr, "hsactl: no status from axis '%s' within 3 s (is hsad running?)\n", session.axis().c_str());
    return 2;
  }
  session.run_until(200ms, [&] { return session.telemetry().has_value(); });
  const hsa::status_t& s = *session.status();
  if (json) {
    std::printf("%s\n", status_json(session.axis(), s, session.telemetry() ? &*session.telemetry() : nullptr).dump().c_str());
    return 0;
  }
  std::printf("axis %s: %s, mode %s%s\n", session.axis().c_str(), hsa::ctl::state_name(s.state),
              mode_name(s.mode), s.holding ? " (holding: setpoints silent)" : "");
  for (int i = 0; i < s.num_faults; ++i) std::printf("  fault: %s\n", s.fault_reason[i].c_str());
  if (session.telemetry()) {
    const hsa::telemetry_t& t = *session.telemetry();
    std::printf("  rod %.3f mm, setpoint %.3f mm, error %+.3f mm, valve %+.3f, pA %.2f bar, pB %.2f bar\n",
                t.position_m * 1e3, t.setpoint_m * 1e3, t.following_error_m * 1e3, t.valve_opening,
                t.pressure_a_pa / 1e5, t.pressure_b_pa / 1e5);
  }
  std::printf("  messages: %lld setpoints accepted; rejected %lld non-finite, %lld out of range, %lld undecodable, "
              "%lld unknown\n",
              static_cast<long long>(s.setpoints_accepted), static_cast<long long>(s.rejected_non_finite),
              static_cast<long long>(s.rejected_out_of_range), static_cast<long long>(s.rejected_decode),
              static_cast<long long>(s.rejected_unknown));
  if (s.auth_required) {
    std::printf("  operators: authenticated; refused %lld unknown operator, %lld bad MAC, %lld replayed, %lld "
                "stale stamp\n",
                static_cast<long long>(s.rejected_unknown_operator), static_cast<long long>(s.rejected_bad_mac),
                static_cast<long long>(s.rejected_replay), static_cast<long long>(s.rejected_stamp));
  }
  if (!s.warning.empty()) std::printf("  WARNING: %s\n", s.warning.c_str());
  if (s.lease_holder.empty()) {
    std::printf("  lease: free (any operator commands the axis); %lld messages refused for a lease\n",
                static_cast<long long>(s.rejected_lease));
  } else {
    std::printf("  lease: held by %s, %.1f s left; %lld messages from others refused\n", s.lease_holder.c_str(),
                s.lease_remaining_s, static_cast<long long>(s.rejected_lease));
  }
  std::printf("  gains: kp %g 1/m, ki %g 1/(m s); %lld changes applied, %lld refused%s%s\n", s.kp, s.ki,
              static_cast<long long>(s.gain_changes_applied), static_cast<long long>(s.gain_changes_refused),
              s.gains_refusal.empty() ? "" : " (last: ", s.gains_refusal.empty() ? "" : (s.gains_refusal + ")").c_str());
  std::printf("  real time: SCHED_FIFO %s, memory %s; overruns %lld, RT allocations %lld, locks %lld, page faults "
              "%lld minor / %lld major\n",
              s.sched_fifo ? "granted" : "REFUSED", s.memory_locked ? "locked" : "NOT locked",
              static_cast<long long>(s.rt_overruns), static_cast<long long>(s.rt_allocations),
              static_cast<long long>(s.rt_locks), static_cast<long long>(s.rt_minor_faults),
              static_cast<long long>(s.rt_major_faults));
  return 0;
}

// A live view, redrawn at 10 Hz, until Ctrl-C or the duration ends.
int watch(LcmSession& session, double duration_s) {
  const auto start = std::chrono::steady_clock::now();
  while (!g_interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
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
      std::printf("  setpoint   %9.3f mm\n  rod        %9.3f mm   [%s]\n", t.setpoint_m * 1e3, t.position_m * 1e3,
                  bar.c_str());
      std::printf("  error      %+9.3f mm\n  velocity   %+9.2f mm/s\n", t.following_error_m * 1e3, t.velocity_m_s * 1e3);
      std::printf("  valve      %+9.3f opening   current %.3f A   spool %+.3f mm   %s\n", t.valve_opening,
                  t.current_ref_a, t.spool_position_m * 1e3, t.valve_enabled ? "enabled" : "DISABLED");
      std::printf("  pressure   A %6.2f bar   B %6.2f bar   load %6.2f bar\n", t.pressure_a_pa / 1e5,
                  t.pressure_b_pa / 1e5, t.load_pressure_pa / 1e5);
      std::printf("  timing     lateness %6.1f µs (max %.1f)   exec %5.1f µs (max %.1f)   overruns %lld\n",
                  t.lateness_ns / 1e3, t.lateness_max_ns / 1e3, t.exec_time_ns / 1e3, t.exec_time_max_ns / 1e3,
                  static_cast<long long>(t.overruns));
    }
    if (session.status()) {
      for (int i = 0; i < session.status()->num_faults; ++i)
        std::printf("  FAULT      %s\n", session.status()->fault_reason[i].c_str());
    }
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
  while (!g_interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s))
    session.poll(50ms);
  session.on_telemetry = nullptr;
  std::printf("%s: %llu telemetry samples written to %s\n", session.axis().c_str(),
              static_cast<unsigned long long>(rows), path.c_str());
  return rows > 0 ? 0 : 1;
}

int log_to_csv(const std::string& log_path, const std::string& axis, const std::string& csv_path) {
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
  for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) {
    if (e->channel != channel) continue;
    hsa::telemetry_t t;
    if (e->datalen < 0 || !hsa::msgs::decode_exact(t, e->data, static_cast<std::size_t>(e->datalen))) {
      ++undecodable;
      continue;
    }
    hsa::ctl::write_telemetry_csv_row(out, t);
    ++rows;
  }
  std::printf("%s: %llu telemetry samples of %s written to %s", log_path.c_str(),
              static_cast<unsigned long long>(rows), channel.c_str(), csv_path.c_str());
  if (undecodable) std::printf(" (%llu undecodable skipped)", static_cast<unsigned long long>(undecodable));
  std::printf("\n");
  return rows > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hsactl: operate an hsad axis over LCM (positions in mm, pressures in bar)"};
  app.require_subcommand(1);
  std::string axis = "lift";
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  app.add_option("--axis", axis, "axis name (its LCM channels are HSA/<axis>/...)")->capture_default_str();
  app.add_option("--lcm-url", url, "LCM provider URL")->capture_default_str();
  std::string key_path;
  app.add_option("--key", key_path, "the operator's key file (<operator>.key) that signs setpoints and commands")
      ->envname("HSA_KEY");

  std::string key_name, key_dir = ".";
  auto* keygen = app.add_subcommand("keygen", "make a new operator key NAME.key (mode 0600) in DIR");
  keygen->add_option("NAME", key_name, "operator id: 1 to 32 of [A-Za-z0-9_.-]")->required();
  keygen->add_option("--dir", key_dir, "folder to write it to")->capture_default_str();

  auto* enable = app.add_subcommand("enable", "enable the axis (it holds where it is)");
  auto* disable = app.add_subcommand("disable", "disable the axis (valve to its safe state)");
  auto* reset = app.add_subcommand("reset", "clear latched faults whose cause is gone");
  bool force = false;
  auto* acquire = app.add_subcommand("acquire", "take the axis: only this operator commands it until released");
  acquire->add_flag("--force", force, "take it even from another operator (hsad logs it)");
  auto* release = app.add_subcommand("release", "give the axis back");
  std::string mode_arg;
  auto* mode = app.add_subcommand("mode", "select the control mode: closed-loop position or open-loop valve opening");
  mode->add_option("MODE", mode_arg, "position | open-loop")
      ->required()
      ->check(CLI::IsMember({"position", "open-loop"}));
  double opening = 0, open_s = 1;
  auto* open = app.add_subcommand("open", "open loop: command a valve opening for a while, then 0");
  open->add_option("OPENING", opening, "valve opening in [-1, 1]")->required()->check(CLI::Range(-1.0, 1.0));
  open->add_option("--duration", open_s, "s")->capture_default_str()->check(CLI::PositiveNumber);
  double position_mm = 0, amplitude_mm = 0, frequency_hz = 0, duration_s = 10, tolerance_mm = 0.1, timeout_s = 10;
  auto* move = app.add_subcommand("move", "move to a position and wait until it is reached");
  move->add_option("POS", position_mm, "target position, mm")->required();
  auto* step = app.add_subcommand("step", "step by AMPL mm from the current position and wait");
  step->add_option("AMPL", amplitude_mm, "step, mm (negative: down)")->required();
  for (auto* cmd : {move, step}) {
    cmd->add_option("--tolerance", tolerance_mm, "reached when within this, mm")->capture_default_str();
    cmd->add_option("--timeout", timeout_s, "give up after, s")->capture_default_str();
  }
  auto* sine_cmd = app.add_subcommand("sine", "track a sine around the current position");
  sine_cmd->add_option("AMPL", amplitude_mm, "amplitude, mm")->required()->check(CLI::PositiveNumber);
  sine_cmd->add_option("FREQ", frequency_hz, "frequency, Hz")->required()->check(CLI::PositiveNumber);
  sine_cmd->add_option("--duration", duration_s, "s")->capture_default_str();
  double kp = 0, ki = 0;
  auto* gains_cmd = app.add_subcommand("gains", "set the cylinder PI's gains (within the axis's max_kp, max_ki)");
  gains_cmd->add_option("KP", kp, "proportional gain, 1/m")->required();
  gains_cmd->add_option("KI", ki, "integral gain, 1/(m s)")->required();
  bool json = false;
  auto* status_cmd = app.add_subcommand("status", "print the axis status");
  status_cmd->add_flag("--json", json, "as one JSON object");
  auto* watch_cmd = app.add_subcommand("watch", "live view of the axis");
  double watch_s = 1e9;
  watch_cmd->add_option("--duration", watch_s, "stop after, s (default: until Ctrl-C)");
  std::string csv, log_path;
  auto* record_cmd = app.add_subcommand("record", "write telemetry to CSV");
  record_cmd->add_option("FILE", csv, "CSV file")->required();
  record_cmd->add_option("--duration", duration_s, "s")->capture_default_str();
  auto* log2csv = app.add_subcommand("log2csv", "turn an lcm-logger log into telemetry CSV");
  log2csv->add_option("LOG", log_path, "LCM log file")->required()->check(CLI::ExistingFile);
  log2csv->add_option("FILE", csv, "CSV file")->required();
  CLI11_PARSE(app, argc, argv);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    if (*log2csv) return log_to_csv(log_path, axis, csv);
    if (*keygen) {
      std::printf("%s\n", hsa::msgs::write_new_key(key_dir, key_name).c_str());
      return 0;
    }
    LcmSession session(url, axis);
    if (!key_path.empty()) session.set_key(hsa::msgs::read_key_file(key_path));
    const bool sends = *enable || *disable || *reset || *mode || *open || *move || *step || *sine_cmd || *gains_cmd ||
                       *acquire || *release;
    if (sends) {
      // Unsigned messages to a daemon that requires signatures would only be counted and dropped.
      if (!first_status(session, app.get_subcommands().front()->get_name().c_str())) return 2;
      if (session.status()->auth_required && !session.signing()) {
        std::fprintf(stderr, "hsactl: axis '%s' obeys signed commands only: give --key FILE (or set HSA_KEY)\n",
                     axis.c_str());
        return 1;
      }
      // Another operator's lease refuses everything but DISABLE and a forced ACQUIRE: say so now.
      const std::string& holder = session.status()->lease_holder;
      if (!holder.empty() && holder != session.operator_id() && !*disable && !(*acquire && force)) {
        std::fprintf(stderr, "hsactl: axis '%s' is held by operator '%s' (hsactl acquire --force takes it over)\n",
                     axis.c_str(), holder.c_str());
        return 1;
      }
    }
    if (*enable) return command_and_confirm(session, hsa::command_t::ENABLE, hsa::status_t::STATE_ENABLED, "enable");
    if (*disable)
      return command_and_confirm(session, hsa::command_t::DISABLE, hsa::status_t::STATE_DISABLED, "disable");
    if (*reset) return command_and_confirm(session, hsa::command_t::RESET, hsa::status_t::STATE_DISABLED, "reset");
    if (*acquire) return lease_command(session, true, force);
    if (*release) return lease_command(session, false, false);
    if (*mode)
      return mode_and_confirm(session, mode_arg == "position" ? hsa::command_t::MODE_POSITION
                                                              : hsa::command_t::MODE_VALVE_OPENING);
    if (*status_cmd) return status(session, json);
    if (*gains_cmd) return gains_and_confirm(session, kp, ki);
    if (*watch_cmd) return watch(session, watch_s);
    if (*record_cmd) return record(session, csv, duration_s);
    if (!wait_for_telemetry(session)) return 2;
    if (*open) return open_valve(session, opening, open_s);
    if (*move) return move_to(session, position_mm * 1e-3, tolerance_mm * 1e-3, timeout_s);
    if (*step)
      return move_to(session, session.telemetry()->position_m + amplitude_mm * 1e-3, tolerance_mm * 1e-3, timeout_s);
    if (*sine_cmd) return sine(session, amplitude_mm * 1e-3, frequency_hz, duration_s);
  } catch (const hsa::msgs::KeyFileError& e) {
    std::fprintf(stderr, "hsactl: key: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
