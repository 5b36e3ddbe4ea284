// hsactl's commands that change the axis. Each waits for hsad's acknowledgement of its counter (and
// for the status to confirm the change), sends again when none comes, and returns non-zero with
// hsad's reason printed when it refuses; every wait is bounded. Only a status hsactl believes
// (lcm_session.hpp) answers: a success, a state, a lease holder or a result is never printed from
// one it could not verify. Positions in m here, mm on screen.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

// hsactl's exit code when hsad's answer could not be verified: it had no key, or what came
// failed verification (docs/man/hsactl.1, EXIT STATUS).
inline constexpr int kExitUnverified = 3;

// Waits for the axis's first status hsactl believes, so a command knows the state it changes and
// the daemon it is for; false (with a message naming what came instead) when none comes.
[[nodiscard]] bool first_status(LcmSession& session, const char* verb);
// `code`, or kExitUnverified when statuses failed verification meanwhile: hsactl got answers it
// could not believe.
[[nodiscard]] int no_answer_code(const LcmSession& session, int code);
// Prints "hsactl: <what>" and what failed verification meanwhile; returns no_answer_code(code).
int no_verified_answer(const LcmSession& session, const std::string& what, int code);
// Waits for the first telemetry sample and a believed status that carries the rod's position
// (commands that start from it).
[[nodiscard]] bool wait_for_telemetry(LcmSession& session);

// After a failure: the faults of the status believed, and what failed verification meanwhile.
void print_faults(const LcmSession& session);
// Delivers a command (by `send`, which returns its counter; sent again when no acknowledgement
// comes) and waits for the axis's answer to it (status_t.result_*, found by this operator and the
// command's counter): 0 when the axis carried it out; otherwise its reason is printed (with the
// faults that explain it) and the exit code returned.
int carry_out(LcmSession& session, const std::function<std::int64_t()>& send, const char* verb);

// The axis left ENABLED (as a believed status says): prints why (its faults), returns 1.
int not_enabled(const LcmSession& session);

int command_and_confirm(LcmSession& session, std::int8_t command, std::int8_t want, const char* verb);
int lease_command(LcmSession& session, bool acquire, bool force);
int mode_and_confirm(LcmSession& session, std::int8_t mode);
int gains_and_confirm(LcmSession& session, double kp, double ki);
int open_valve(LcmSession& session, double opening, double duration_s);
// How `move` and `step` get there.
struct MoveOptions {
  double speed_m_s = 0.0;    // 0: the axis's max_speed_m_s
  double accel_m_s2 = 0.0;   // 0: that speed reached in 0.1 s
  double tolerance_m = 1e-4; // reached when within this for 0.2 s
  double timeout_s = 10.0;
  bool stream = false;       // stream setpoints at 100 Hz instead of one MOVE_TO
};
int move_to(LcmSession& session, double target_m, const MoveOptions& move);
int sine(LcmSession& session, double amplitude_m, double frequency_hz, double duration_s);

}  // namespace hsa::ctl
