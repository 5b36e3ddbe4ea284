#include "tools/hsactl/axis_commands.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <thread>

#include "tools/hsactl/interrupt.hpp"

namespace hsa::ctl {

using namespace std::chrono_literals;

void print_faults(const LcmSession& session) {
  const hsa::status_t& s = *session.status();
  for (int i = 0; i < s.num_faults; ++i) std::fprintf(stderr, "  fault: %s\n", s.fault_reason[i].c_str());
  if (session.verifier().failed() > 0) {
    std::fprintf(stderr, "  meanwhile received %s\n", session.verifier().failures().c_str());
  }
}

namespace {

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

// Sends a command (by `send`, which returns its counter) until hsad acknowledges it in a status
// hsactl believes: a datagram can be lost, so without an acknowledgement or a refusal within 0.5 s
// it sends it again (a new message with a new counter), three times in all. `counter` is then the
// acknowledged one. Returns 0, or the exit code when hsad refused the message (its reason printed)
// or no believed answer came (said so, with what came instead).
int deliver(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb, std::int64_t& counter) {
  if (!first_status(session, verb)) return no_answer_code(session, 2);
  const hsa::status_t before = *session.status();
  for (int attempt = 0; attempt < 3; ++attempt) {
    counter = send();
    std::string why;
    const bool answered = session.run_until(500ms, [&] {
      const auto ack = session.acknowledged(*session.status());
      if (ack && *ack >= counter) return true;
      why = refusal(session, before, *session.status());
      return !why.empty();
    });
    if (answered && why.empty()) return 0;
    if (answered) {
      std::fprintf(stderr, "hsactl: %s refused: %s%s\n", verb, why.c_str(), session.unverified_tag());
      print_faults(session);
      return 1;
    }
  }
  return no_verified_answer(session, std::string(verb) + ": no " + (session.can_verify() ? "verified " : "") +
                                         "acknowledgement from axis '" + session.axis() + "', sent 3 times in 1.5 s",
                            1);
}

}  // namespace

int carry_out(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb) {
  std::int64_t counter = 0;
  if (const int code = deliver(session, send, verb, counter); code != 0) return code;
  std::optional<std::size_t> answer;
  if (!session.run_until(3s, [&] { return (answer = session.answer_to(*session.status(), counter)).has_value(); })) {
    return no_verified_answer(session, std::string(verb) + ": axis '" + session.axis() +
                                           "' took it but gave no answer within 3 s",
                              1);
  }
  const hsa::status_t& s = *session.status();
  if (s.result_accepted.at(*answer)) return 0;
  std::fprintf(stderr, "hsactl: %s refused: %s%s\n", verb, s.result_reason.at(*answer).c_str(), session.unverified_tag());
  print_faults(session);
  return 1;
}

int no_answer_code(const LcmSession& session, int code) {
  return session.verifier().failed() > 0 ? kExitUnverified : code;
}

int no_verified_answer(const LcmSession& session, const std::string& what, int code) {
  const std::string failures = session.verifier().failures();
  std::fprintf(stderr, "hsactl: %s%s%s\n", what.c_str(), failures.empty() ? "" : "; received ", failures.c_str());
  return no_answer_code(session, code);
}

// Waits for a first status hsactl believes: the baseline a refusal is judged against, and, from
// its system and instance, the daemon the commands are signed for. False (and says so, naming what
// came instead) when none comes.
bool first_status(LcmSession& session, const char* verb) {
  if (session.status()) return true;
  if (session.run_until(2s, [&] { return session.status().has_value(); })) return true;
  if (session.verifier().failed() > 0) {
    no_verified_answer(session, std::string(verb) + ": no verified status from axis '" + session.axis() +
                                    "' within 2 s",
                       2);
    return false;
  }
  if (session.axes_heard().empty()) {
    std::fprintf(stderr, "hsactl: %s: no status from axis '%s' within 2 s, nor from any other axis (is hsad "
                 "running, on this LCM URL?)\n", verb, session.axis().c_str());
    return false;
  }
  std::string others;
  for (const auto& [name, heard] : session.axes_heard()) others += (others.empty() ? "" : ", ") + name;
  std::fprintf(stderr, "hsactl: %s: no axis '%s'; the axes that answer: %s (give --axis NAME)\n", verb,
               session.axis().c_str(), others.c_str());
  return false;
}

// Sends a command and waits until the status reports `want` (or a state that rules it out).
int command_and_confirm(LcmSession& session, std::int8_t command, std::int8_t want, const char* verb) {
  if (const int code = carry_out(session, [&] { return session.send_command(command); }, verb); code != 0) return code;
  const bool confirmed = session.run_until(3s, [&] { return session.status()->state == want; });
  if (confirmed) {
    std::printf("%s: %s%s\n", session.axis().c_str(), hsa::ctl::state_name(want), session.unverified_tag());
    return 0;
  }
  std::fprintf(stderr, "hsactl: %s refused: axis '%s' is %s%s\n", verb, session.axis().c_str(),
               hsa::ctl::state_name(session.status()->state), session.unverified_tag());
  print_faults(session);
  return 1;
}

// ACQUIRE (with --force: from its holder) or RELEASE the axis's lease.
int lease_command(LcmSession& session, bool acquire, bool force) {
  const char* verb = acquire ? "acquire" : "release";
  const std::int8_t command = acquire ? hsa::command_t::ACQUIRE : hsa::command_t::RELEASE;
  std::int64_t counter = 0;
  if (const int code = deliver(session, [&] { return session.send_command(command, 0, 0.0, force); }, verb, counter);
      code != 0) {
    return code;
  }
  const hsa::status_t& s = *session.status();
  if (acquire) {
    std::printf("%s: held by %s (lease %.0f s, renewed by each of its commands)%s\n", session.axis().c_str(),
                s.lease_holder.c_str(), s.lease_remaining_s, session.unverified_tag());
  } else {
    std::printf("%s: released%s\n", session.axis().c_str(), session.unverified_tag());
  }
  return 0;
}

// Sends a MODE command and waits until the status reports the mode.
int mode_and_confirm(LcmSession& session, std::int8_t mode) {
  if (const int code = carry_out(session, [&] { return session.send_command(hsa::command_t::MODE, mode, 0.0); }, "mode");
      code != 0) {
    return code;
  }
  if (session.run_until(3s, [&] { return session.status()->mode == mode; })) {
    std::printf("%s: mode %s%s\n", session.axis().c_str(), mode_name(mode), session.unverified_tag());
    return 0;
  }
  std::fprintf(stderr, "hsactl: mode %s not confirmed: axis '%s' is %s in mode %s%s\n", mode_name(mode),
               session.axis().c_str(), hsa::ctl::state_name(session.status()->state),
               mode_name(session.status()->mode), session.unverified_tag());
  print_faults(session);
  return 1;
}

// Sends GAINS and waits until the status counts it applied or refused by the axis (with its
// reason); the daemon's message checks (NaN, kp <= 0, ki < 0) refuse it before that.
int gains_and_confirm(LcmSession& session, double kp, double ki) {
  if (!first_status(session, "gains")) return no_answer_code(session, 2);
  const hsa::status_t before = *session.status();
  std::int64_t counter = 0;
  if (const int code = deliver(session, [&] { return session.send_gains(kp, ki); }, "gains", counter); code != 0) {
    return code;
  }
  const bool answered = session.run_until(3s, [&] {
    const hsa::status_t& s = *session.status();
    return s.gain_changes_applied > before.gain_changes_applied ||
           s.gain_changes_refused > before.gain_changes_refused;
  });
  const hsa::status_t& s = *session.status();
  if (answered && s.gain_changes_applied > before.gain_changes_applied) {
    std::printf("%s: gains kp %g 1/m, ki %g 1/(m s)%s\n", session.axis().c_str(), s.kp, s.ki, session.unverified_tag());
    return 0;
  }
  if (!answered) {
    return no_verified_answer(session, "gains not confirmed by axis '" + session.axis() + "' within 3 s", 1);
  }
  std::fprintf(stderr, "hsactl: gains refused: %s%s\n", s.gains_refusal.c_str(), session.unverified_tag());
  print_faults(session);
  return 1;
}

// The rod's position as the last believed status has it (from hsad's latest telemetry sample):
// telemetry itself is not authenticated, so what hsactl reports and starts from comes from here.
double status_position_m(const LcmSession& session) { return session.status()->position_m; }

// Waits for a believed status that arrives after this call (at most 1 s): what hsactl says last
// is what hsad says now. False when none came.
bool fresh_status(LcmSession& session) {
  const std::uint64_t seen = session.status_count();
  return session.run_until(1s, [&] { return session.status_count() > seen; });
}

// The axis left ENABLED (as a believed status says): print why, return 1.
int not_enabled(const LcmSession& session) {
  std::fprintf(stderr, "hsactl: axis '%s' is %s, not ENABLED%s\n", session.axis().c_str(),
               hsa::ctl::state_name(session.status()->state), session.unverified_tag());
  print_faults(session);
  return 1;
}

namespace {

// Sends MODE with a valve opening; hsad holds it `duration_s` (0: until the next opening or its
// setpoint timeout) and then commands opening 0 itself.
std::int64_t send_opening(LcmSession& session, double opening, double duration_s) {
  return session.send(hsa::command_t::MODE, [&](hsa::command_t& msg) {
    msg.mode = hsa::command_t::MODE_VALVE_OPENING;
    msg.valve_opening = opening;
    msg.opening_duration_s = duration_s;
  });
}

}  // namespace

// Open loop: one MODE command carries the opening and its duration, and hsad's RT loop ends it, so
// the valve holds it for the duration to the base tick, however late this process's messages would
// arrive. hsactl waits that long and watches that the axis stays ENABLED; Ctrl-C closes the valve
// at once. Fails when the axis is not ENABLED or leaves it.
int open_valve(LcmSession& session, double opening, double duration_s) {
  // Switching the mode is the axis's to refuse; that it must be ENABLED to open is hsactl's to
  // check first, so a refused open changes nothing.
  if (!first_status(session, "open")) return no_answer_code(session, 2);
  if (session.status()->state != hsa::status_t::STATE_ENABLED) {
    std::fprintf(stderr, "hsactl: open refused: axis '%s' is %s, not ENABLED (hsactl enable first)%s\n",
                 session.axis().c_str(), hsa::ctl::state_name(session.status()->state), session.unverified_tag());
    print_faults(session);
    return 1;
  }
  const double start_m = status_position_m(session);
  if (const int code = carry_out(session, [&] { return send_opening(session, opening, duration_s); }, "open");
      code != 0) {
    return code;
  }
  // The answer comes after the cycle that opened the valve: the opening ends within duration_s.
  const bool ended_early = session.run_until(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                 std::chrono::duration<double>(duration_s)),
                                             [&] {
                                               return interrupted ||
                                                      session.status()->state != hsa::status_t::STATE_ENABLED;
                                             });
  if (interrupted) {
    send_opening(session, 0.0, 0.0);
    return 130;
  }
  if (ended_early) return not_enabled(session);
  if (!fresh_status(session)) return no_verified_answer(session, "open: no status after the opening", 1);
  std::printf("%s: opening %+.3f for %.3f s (timed by hsad): rod %.3f mm -> %.3f mm%s\n", session.axis().c_str(),
              opening, duration_s, start_m * 1e3, status_position_m(session) * 1e3, session.unverified_tag());
  return 0;
}

bool wait_for_telemetry(LcmSession& session) {
  if (session.run_until(3s, [&] { return session.telemetry().has_value(); })) {
    // The rod's position hsactl starts from and reports is the one hsad's status carries.
    if (session.status() && session.run_until(1s, [&] { return session.status()->sample_utime != 0; })) return true;
    no_verified_answer(session, "axis '" + session.axis() + "': no rod position in its status within 1 s", 2);
    return false;
  }
  if (!session.status()) return first_status(session, "telemetry");  // says which axes answer
  std::fprintf(stderr, "hsactl: axis '%s' sends status but no telemetry within 3 s\n", session.axis().c_str());
  return false;
}

// Sends MOVE_TO (hsad generates the trajectory and holds the target) or, with `move.stream`,
// streams the target at 100 Hz as a real-time client does; then waits until the rod has stayed
// within the tolerance of the target for 0.2 s (judged on telemetry, 1 kHz), and confirms it from
// a believed status (telemetry is not authenticated), or the timeout passes. A refused MOVE_TO is
// printed with the axis's reason at once; the axis leaving ENABLED ends the wait.
int move_to(LcmSession& session, double target_m, const MoveOptions& move) {
  if (!first_status(session, "move")) return no_answer_code(session, 2);
  const hsa::status_t before = *session.status();
  if (!move.stream) {
    const int code =
        carry_out(session, [&] { return session.send_move_to(target_m, move.speed_m_s, move.accel_m_s2); }, "move");
    if (code != 0) return code;
  }
  const double tolerance_m = move.tolerance_m;
  const double timeout_s = move.timeout_s;
  const auto start = std::chrono::steady_clock::now();
  auto inside_since = start;
  bool inside = false;
  while (!interrupted) {
    if (move.stream) session.send_setpoint(target_m);
    session.poll(10ms);
    const auto now = std::chrono::steady_clock::now();
    if (session.status()->state != hsa::status_t::STATE_ENABLED) return not_enabled(session);
    const bool near = std::abs(session.telemetry()->position_m - target_m) <= tolerance_m;
    if (near && !inside) inside_since = now;
    inside = near;
    if (inside && now - inside_since >= 200ms) {
      // hsad's word for it: a status sent after the dwell, with the rod within the tolerance.
      const bool confirmed = fresh_status(session) &&
                             std::abs(status_position_m(session) - target_m) <= tolerance_m &&
                             session.status()->state == hsa::status_t::STATE_ENABLED;
      if (confirmed) {
        std::printf("%s: at %.3f mm (target %.3f mm)%s\n", session.axis().c_str(), status_position_m(session) * 1e3,
                    target_m * 1e3, session.unverified_tag());
        return 0;
      }
      inside = false;  // telemetry said so, hsad did not: keep waiting until the timeout
    }
    if (now - start > std::chrono::duration<double>(timeout_s)) {
      char what[160];
      std::snprintf(what, sizeof what, "move timed out after %.1f s at %.3f mm (target %.3f mm)", timeout_s,
                    status_position_m(session) * 1e3, target_m * 1e3);
      const int code = no_verified_answer(session, what, 1);
      // The counters are the axis's, not this session's: a hint, given only when it explains.
      const std::string why = refusal(session, before, *session.status());
      if (!why.empty()) std::fprintf(stderr, "  (hsad refused messages meanwhile: %s)\n", why.c_str());
      return code;
    }
  }
  return 130;
}

int sine(LcmSession& session, double amplitude_m, double frequency_hz, double duration_s) {
  const double centre = status_position_m(session);
  double worst = 0.0;
  session.on_telemetry = [&](const hsa::telemetry_t& t) {
    if (t.state == hsa::status_t::STATE_ENABLED) worst = std::max(worst, std::abs(t.following_error_m));
  };
  const auto start = std::chrono::steady_clock::now();
  int code = 0;
  for (long k = 0; !interrupted; ++k) {
    const double t = k * 1e-3;  // 1 kHz setpoint stream
    if (t > duration_s) break;
    session.send_setpoint(centre + amplitude_m * std::sin(2.0 * std::numbers::pi * frequency_hz * t));
    session.poll(0ms);
    if (session.status()->state != hsa::status_t::STATE_ENABLED) {
      code = not_enabled(session);
      break;
    }
    std::this_thread::sleep_until(start + std::chrono::duration<double>(t + 1e-3));
  }
  session.on_telemetry = nullptr;
  if (code != 0) return code;
  if (!fresh_status(session)) return no_verified_answer(session, "sine: no status after the sine", 1);
  if (session.status()->state != hsa::status_t::STATE_ENABLED) return not_enabled(session);
  // The following error is telemetry's (not authenticated); the state at the end is hsad's word.
  std::printf("%s: sine %.3f mm at %.3f Hz for %.1f s around %.3f mm; max |following error| %.3f mm (telemetry)%s\n",
              session.axis().c_str(), amplitude_m * 1e3, frequency_hz, duration_s, centre * 1e3, worst * 1e3,
              session.unverified_tag());
  return interrupted ? 130 : 0;
}

}  // namespace hsa::ctl
