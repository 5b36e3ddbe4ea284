// Fault classes of one axis and the record a fault leaves behind.
//
// The RT thread stores only numbers: the class, which signal, the sample status, the measured
// value and the limit it broke. A normal thread turns a record into a sentence with describe()
// ("pressure A 27.1 bar over limit 26.0 bar"), so no string is built in the cycle.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "drivers/sample_status.hpp"

namespace hsa::daemon {

// Ordered by priority: when several trip in one cycle the first in this list is latched.
enum class FaultReason : std::uint8_t {
  none,
  estop,              // e-stop input asserted or unreadable → ESTOP
  driver_error,       // the executive reports a failed driver read/write
  control_output,     // the loops produced a non-finite command (NaN or ±Inf)
  blind_time,         // ENABLED: the time since the last cycle exceeded its bound
  rt_overruns,        // a streak of RT overruns at or over its limit
  sensor_not_ok,      // a sample's status is not ok, or no new timestamp for too long (signal says which)
  encoder_stale,      // encoder timestamp unchanged for too many cycles
  encoder_jump,       // |Δposition| between two samples over max speed × their Δt + margin
  over_pressure,      // pressure A or B over its limit
  soft_limit,         // rod position outside its soft limits (ENABLED only)
  following_error,    // |setpoint − position| over its limit for too long (position mode)
  current_saturated,  // valve command saturated for too long
  inputs_not_ready,   // INIT: an input gave no first sample within the start-up timeout
};
inline constexpr int kFaultReasonCount = 14;

// Bit of a reason in a mask of active faults.
constexpr std::uint32_t fault_bit(FaultReason r) { return 1u << static_cast<unsigned>(r); }

enum class FaultSignal : std::uint8_t { none, position, pressure_a, pressure_b, spool, estop };

struct FaultRecord {
  FaultReason reason = FaultReason::none;
  FaultSignal signal = FaultSignal::none;
  io::SampleStatus status = io::SampleStatus::ok;  // for sensor_not_ok
  // SI (m, Pa, s) or a count of cycles, depending on the reason: blind_time and a sensor_not_ok
  // with status stale carry seconds (the gap, the age); control_output the command written;
  // inputs_not_ready the seconds waited (value) and the start-up timeout (limit).
  double value = 0.0;
  double limit = 0.0;
  std::int64_t t_ns = 0;  // cycle time of the trip
};

// "over_pressure": a stable identifier for status and logs.
std::string_view to_string(FaultReason reason) noexcept;
// "pressure over its limit": a static sentence for the class.
std::string_view summary(FaultReason reason) noexcept;
std::string_view to_string(FaultSignal signal) noexcept;  // "pressure A"
// The full sentence with numbers in mm and bar. Allocates: never call it on the RT thread.
std::string describe(const FaultRecord& record);

}  // namespace hsa::daemon
