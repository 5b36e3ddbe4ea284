// From the RT thread's plain samples to the LCM types the bridge publishes.
//
// Runs on the LCM thread (it allocates: status_t holds strings and vectors). Pure functions, so
// the field mapping is tested without a network.
#pragma once

#include <cstdint>

#include "daemon/lcm_bridge/axis_port.hpp"
#include "daemon/lcm_bridge/rt_messages.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::daemon {

[[nodiscard]] hsa::telemetry_t to_lcm(const TelemetrySample& sample);

// The RT side's status, the bridge's counters, stamped with `utime_us` (the publish time).
[[nodiscard]] hsa::status_t to_lcm(const StatusSample& sample, const AxisCounters& counters, std::int64_t utime_us);

// Whether `next` differs from `previous` in what an operator must see at once: state, mode, hold
// or the set of active fault codes. Counters, timestamps and the wording of reasons (which may
// carry live values) are not changes; they go out with the periodic status.
[[nodiscard]] bool status_changed(const StatusSample& previous, const StatusSample& next);

}  // namespace hsa::daemon
