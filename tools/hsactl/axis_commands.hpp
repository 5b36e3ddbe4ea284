// hsactl's commands that change the axis. Each waits for hsad's acknowledgement of its counter (and
// for the status to confirm the change), sends again when none comes, and returns non-zero with
// hsad's reason printed when it refuses; every wait is bounded. Positions in m here, mm on screen.
#pragma once

#include <cstdint>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

// Waits for the axis's first status, so a command knows the state it changes; false (with a
// message) when none comes.
[[nodiscard]] bool first_status(LcmSession& session, const char* verb);
// Waits for the first telemetry sample (commands that start from the rod's position).
[[nodiscard]] bool wait_for_telemetry(LcmSession& session);

int command_and_confirm(LcmSession& session, std::int8_t command, std::int8_t want, const char* verb);
int lease_command(LcmSession& session, bool acquire, bool force);
int mode_and_confirm(LcmSession& session, std::int8_t mode);
int gains_and_confirm(LcmSession& session, double kp, double ki);
int open_valve(LcmSession& session, double opening, double duration_s);
int move_to(LcmSession& session, double target_m, double tolerance_m, double timeout_s);
int sine(LcmSession& session, double amplitude_m, double frequency_hz, double duration_s);

}  // namespace hsa::ctl
