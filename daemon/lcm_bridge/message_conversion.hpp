// From the axis port's plain samples (telemetry from the RT thread, status from the operator
// thread) to the LCM types the bridge publishes: the one place the supervisor's states, modes and
// fault classes become the wire's constants.
//
// Runs on the LCM thread (it allocates: status_t holds strings and vectors). Pure functions, so
// the field mapping is tested without a network.
#pragma once

#include <cstdint>

#include "daemon/axis/axis_port.hpp"
#include "daemon/axis/port_messages.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::daemon {

[[nodiscard]] hsa::telemetry_t to_lcm(const TelemetrySample& sample);

// The operator thread's status, the bridge's counters, stamped with `utime_us` (the publish time).
[[nodiscard]] hsa::status_t to_lcm(const StatusSample& sample, const AxisCounters& counters, std::int64_t utime_us);

// Whether `next` differs from `previous` in what an operator must see at once: state, mode, hold,
// the fault class, or a new answer to a command. Counters, timestamps and the wording of reasons (which may
// carry live values) are not changes; they go out with the periodic status.
[[nodiscard]] bool status_changed(const StatusSample& previous, const StatusSample& next);

}  // namespace hsa::daemon
