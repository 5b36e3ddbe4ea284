// Fault classes of one axis and the record a fault leaves behind.
//
// The classes are one table, HSA_FAULT_REASONS below: the enum, its count, the status code each
// class goes out with, what a reset needs of it, its sentence and how its numbers are written
// all come from that one line, so a new fault on existing inputs is a line here and its check in
// AxisSupervisor::evaluate (and a status_t.FAULT_* constant when no existing code fits).
//
// The RT thread stores only numbers: the class, which signal, the sample status, the measured
// value and the limit it broke. A normal thread turns a record into a sentence with describe()
// ("pressure A 27.1 bar over limit 26.0 bar"), so no string is built in the cycle.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "daemon/supervisor/axis_inputs.hpp"
#include "drivers/sample_status.hpp"

namespace hsa::daemon {

// What a class of fault asks of the state machine (flags of the table's `kind` column).
namespace fault_kind {
inline constexpr std::uint8_t transient = 0;       // gone once the loops are frozen: a reset clears it
inline constexpr std::uint8_t persistent = 1;      // its cause outlives the fault: a reset waits for it to clear
inline constexpr std::uint8_t enabled_only = 2;    // can only arise while the loops drive the valve
inline constexpr std::uint8_t while_starting = 4;  // judged in INIT before every input delivered (needs no input)
}  // namespace fault_kind

// X(reason, wire code (status_t.FAULT_*), kind, summary, detail, scale)
//
// Ordered by priority: when several trip in one cycle the first in this list is latched. `detail`
// is the sentence with numbers, a printf format of the record's value and limit, each multiplied
// by `scale` (1e3: m → mm, 1e-5: Pa → bar); with a leading "%s" it first takes the signal's name.
// An empty detail is the summary alone; a few classes word their record themselves (describe()).
#define HSA_FAULT_REASONS(X)                                                                                  \
  /* e-stop input asserted or unreadable → ESTOP */                                                          \
  X(estop, FAULT_ESTOP, fault_kind::persistent, "e-stop", "", 1.0)                                            \
  /* the executive reports a failed driver read/write */                                                     \
  X(driver_error, FAULT_DRIVER, fault_kind::persistent | fault_kind::while_starting, "driver error", "", 1.0) \
  /* the loops produced a non-finite command (NaN or ±Inf): value is the command */                          \
  X(control_output, FAULT_CONTROL_OUTPUT, fault_kind::transient, "control output not finite",                \
    "control output not finite (%g): valve set safe", 1.0)                                                    \
  /* ENABLED: the time since the last cycle exceeded its bound (seconds) */                                  \
  X(blind_time, FAULT_BLIND_TIME, fault_kind::enabled_only, "blind time",                                     \
    "blind time: %.1f ms without a cycle (limit %.1f ms)", 1e3)                                               \
  /* a streak of RT overruns at or over its limit */                                                         \
  X(rt_overruns, FAULT_OVERRUNS, fault_kind::persistent | fault_kind::while_starting, "streak of RT overruns", \
    "%.0f consecutive RT overruns (limit %.0f)", 1.0)                                                         \
  /* a sample's status is not ok, or no new timestamp for too long (signal says which) */                    \
  X(sensor_not_ok, FAULT_SENSOR, fault_kind::persistent, "sensor sample not ok", "", 1.0)                     \
  /* encoder timestamp unchanged for too many cycles */                                                      \
  X(encoder_stale, FAULT_ENCODER, fault_kind::persistent, "encoder stale",                                    \
    "encoder stale: no new sample for %.0f cycles (limit %.0f)", 1.0)                                         \
  /* |Δposition| between two samples over max speed × their Δt + margin */                                   \
  X(encoder_jump, FAULT_ENCODER, fault_kind::transient, "encoder jump",                                       \
    "encoder jumped %.2f mm between two samples (limit %.2f mm)", 1e3)                                        \
  /* pressure A or B over its limit */                                                                       \
  X(over_pressure, FAULT_PRESSURE, fault_kind::persistent, "pressure over its limit",                         \
    "%s %.1f bar over limit %.1f bar", 1e-5)                                                                  \
  /* rod position outside its soft limits (ENABLED only) */                                                  \
  X(soft_limit, FAULT_SOFT_LIMIT, fault_kind::enabled_only, "position outside its soft limits",              \
    "position %.2f mm beyond soft limit %.2f mm", 1e3)                                                        \
  /* |setpoint − position| over its limit for too long (position mode) */                                    \
  X(following_error, FAULT_FOLLOWING_ERROR, fault_kind::enabled_only, "following error over its limit",      \
    "following error %.2f mm over limit %.2f mm", 1e3)                                                        \
  /* the valve command (a proportional valve's current, a servo-valve's opening) at its limit too long */    \
  X(current_saturated, FAULT_CURRENT_SATURATION, fault_kind::enabled_only,                                    \
    "valve command saturated for too long", "valve command saturated for %.0f cycles (limit %.0f)", 1.0)     \
  /* INIT: an input gave no first sample within the start-up timeout */                                      \
  X(inputs_not_ready, FAULT_INPUTS_NOT_READY, fault_kind::transient,                                          \
    "an input gave no first sample at start-up", "", 1.0)

enum class FaultReason : std::uint8_t {
  none,
#define HSA_FAULT_ENUMERATOR(reason, wire, kind, summary, detail, scale) reason,
  HSA_FAULT_REASONS(HSA_FAULT_ENUMERATOR)
#undef HSA_FAULT_ENUMERATOR
};

// Every class and none, for arrays indexed by reason.
inline constexpr std::size_t kFaultReasonCount = 1
#define HSA_FAULT_COUNT(reason, wire, kind, summary, detail, scale) +1
    HSA_FAULT_REASONS(HSA_FAULT_COUNT)
#undef HSA_FAULT_COUNT
    ;
// Active faults travel as a 32-bit mask.
static_assert(kFaultReasonCount <= 32, "fault_bit() needs a wider mask");

// Bit of a reason in a mask of active faults.
constexpr std::uint32_t fault_bit(FaultReason r) { return 1u << static_cast<unsigned>(r); }

// The reasons whose table `kind` has any of `flags`, as a mask.
constexpr std::uint32_t fault_mask(std::uint8_t flags) {
  std::uint32_t mask = 0;
#define HSA_FAULT_MASK(reason, wire, kind, summary, detail, scale) \
  if (((kind) & flags) != 0) mask |= fault_bit(FaultReason::reason);
  HSA_FAULT_REASONS(HSA_FAULT_MASK)
#undef HSA_FAULT_MASK
  return mask;
}

// The inputs a fault can name: the axis's input table (axis_inputs.hpp), in its order.
enum class FaultSignal : std::uint8_t {
  none,
#define HSA_FAULT_SIGNAL_ENUMERATOR(signal, name, kind, presence, unreadable) signal,
  HSA_AXIS_INPUTS(HSA_FAULT_SIGNAL_ENUMERATOR)
#undef HSA_FAULT_SIGNAL_ENUMERATOR
};
// The inputs without none, for arrays indexed by signal − 1.
inline constexpr std::size_t kFaultSignalCount = kAxisInputCount;

constexpr FaultSignal fault_signal(AxisInput input) {
  return static_cast<FaultSignal>(static_cast<std::size_t>(input) + 1);
}

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
