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

namespace {

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

// Sends a command (by `send`, which returns its counter) until hsad acknowledges it in its status:
// a datagram can be lost, so without an acknowledgement or a refusal within 0.5 s it sends it
// again (a new message with a new counter), three times in all. The acknowledged counter; nullopt
// when hsad refused the message (its reason printed) or nothing answered (said so).
std::optional<std::int64_t> deliver(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb) {
  if (!first_status(session, verb)) return std::nullopt;
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
    if (answered && why.empty()) return counter;
    if (answered) {
      std::fprintf(stderr, "hsactl: %s refused: %s\n", verb, why.c_str());
      return std::nullopt;
    }
  }
  std::fprintf(stderr, "hsactl: %s: axis '%s' did not acknowledge it, sent 3 times in 1.5 s\n", verb,
               session.axis().c_str());
  return std::nullopt;
}

// Delivers a command and waits for the axis's answer to it (status_t.result_*): true when the axis
// carried it out; otherwise its reason is printed (with the faults that explain it).
bool carry_out(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb) {
  const std::optional<std::int64_t> counter = deliver(session, send, verb);
  if (!counter) return false;
  std::optional<std::size_t> answer;
  if (!session.run_until(3s, [&] { return (answer = session.answer_to(*session.status(), *counter)).has_value(); })) {
    std::fprintf(stderr, "hsactl: %s: axis '%s' took it but gave no answer within 3 s; it is %s\n", verb,
                 session.axis().c_str(), hsa::ctl::state_name(session.status()->state));
    return false;
  }
  const hsa::status_t& s = *session.status();
  if (s.result_accepted.at(*answer)) return true;
  std::fprintf(stderr, "hsactl: %s refused: %s\n", verb, s.result_reason.at(*answer).c_str());
  print_faults(s);
  return false;
}

}  // namespace

// Waits for a first status, the baseline a refusal is judged against; false (and says so) when
// none comes.
bool first_status(LcmSession& session, const char* verb) {
  if (session.run_until(3s, [&] { return session.status().has_value(); })) return true;
  if (session.axes_heard().empty()) {
    std::fprintf(stderr, "hsactl: %s: no status from axis '%s' within 3 s, nor from any other axis (is hsad "
                 "running, on this LCM URL?)\n", verb, session.axis().c_str());
    return false;
  }
  std::string others;
  for (const auto& [name, state] : session.axes_heard()) others += (others.empty() ? "" : ", ") + name;
  std::fprintf(stderr, "hsactl: %s: no axis '%s'; the axes that answer: %s (give --axis NAME)\n", verb,
               session.axis().c_str(), others.c_str());
  return false;
}

// Sends a command and waits until the status reports `want` (or a state that rules it out).
int command_and_confirm(LcmSession& session, std::int8_t command, std::int8_t want, const char* verb) {
  if (!carry_out(session, [&] { return session.send_command(command); }, verb)) return 1;
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
  if (!carry_out(session, [&] { return session.send_command(hsa::command_t::MODE, mode, 0.0); }, "mode")) return 1;
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

// Open loop: the first MODE command opens the valve to `opening` at once; it is repeated at 20 Hz
// for `duration_s` only so that the opening never falls silent (the daemon holds opening 0 after
// its setpoint timeout, 0.5 s by default), then opening 0 is commanded. Fails when the axis is not
// ENABLED or leaves it.
int open_valve(LcmSession& session, double opening, double duration_s) {
  // Switching the mode is the axis's to refuse; that it must be ENABLED to open is hsactl's to
  // check first, so a refused open changes nothing.
  if (!first_status(session, "open")) return 2;
  if (session.status()->state != hsa::status_t::STATE_ENABLED) {
    std::fprintf(stderr, "hsactl: open refused: axis '%s' is %s, not ENABLED (hsactl enable first)\n",
                 session.axis().c_str(), hsa::ctl::state_name(session.status()->state));
    print_faults(*session.status());
    return 1;
  }
  if (!carry_out(session, [&] { return session.send_command(hsa::command_t::MODE, hsa::command_t::MODE_VALVE_OPENING, opening); },
                 "open")) {
    return 1;
  }
  const double start_m = session.telemetry()->position_m;
  const auto start = std::chrono::steady_clock::now();
  int code = 0;
  while (!interrupted && std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
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
  return interrupted ? 130 : code;
}

bool wait_for_telemetry(LcmSession& session) {
  if (session.run_until(3s, [&] { return session.telemetry().has_value(); })) return true;
  if (!session.status()) return first_status(session, "telemetry");  // says which axes answer
  std::fprintf(stderr, "hsactl: axis '%s' sends status but no telemetry within 3 s\n", session.axis().c_str());
  return false;
}

// Sends MOVE_TO (hsad generates the trajectory and holds the target) or, with `move.stream`,
// streams the target at 100 Hz as a real-time client does; then waits until the rod has stayed
// within the tolerance of the target for 0.2 s, or the timeout passes. A refused MOVE_TO is
// printed with the axis's reason at once.
int move_to(LcmSession& session, double target_m, const MoveOptions& move) {
  if (!first_status(session, "move")) return 2;
  const hsa::status_t before = *session.status();
  if (!move.stream &&
      !carry_out(session, [&] { return session.send_move_to(target_m, move.speed_m_s, move.accel_m_s2); }, "move")) {
    return 1;
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
  for (long k = 0; !interrupted; ++k) {
    const double t = k * 1e-3;  // 1 kHz setpoint stream
    if (t > duration_s) break;
    session.send_setpoint(centre + amplitude_m * std::sin(2.0 * std::numbers::pi * frequency_hz * t));
    session.poll(0ms);
    std::this_thread::sleep_until(start + std::chrono::duration<double>(t + 1e-3));
  }
  session.on_telemetry = nullptr;
  std::printf("%s: sine %.3f mm at %.3f Hz for %.1f s around %.3f mm; max |following error| %.3f mm\n",
              session.axis().c_str(), amplitude_m * 1e3, frequency_hz, duration_s, centre * 1e3, worst * 1e3);
  return interrupted ? 130 : 0;
}

}  // namespace hsa::ctl
