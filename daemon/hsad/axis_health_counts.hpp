// What the operator thread counts of one axis for the metrics (docs/monitoring.md), from what it
// already sees at ~100 Hz: the latest telemetry and the axis's answers to commands. Nothing of it
// is counted on the RT thread.
//
// A fault is counted when the telemetry shows a latched record the thread has not counted yet (a
// new reason or a new trip time): one count per latch, whatever the fault's length. A fault that
// latched and was reset between two polls (10 ms) is not seen; a reset needs a command that the
// operator thread itself forwards, so that takes an operator who resets a fault before status
// could have shown it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "daemon/supervisor/command.hpp"
#include "daemon/supervisor/fault.hpp"

namespace hsa::daemon {

// Every Refusal and none, for arrays indexed by it: the enum's last value + 1 (refusal_id() in
// metrics_text.cpp names each and is a switch without default, so a new one is a warning there).
// The last Refusal: a new one goes at the end of the enum and here, and refusal_id() names it.
inline constexpr std::size_t kRefusalCount = static_cast<std::size_t>(Refusal::no_recorder) + 1;

struct AxisHealthCounts {
  std::array<std::uint64_t, kFaultReasonCount> faults{};  // latches, indexed by FaultReason; [none] = 0
  std::array<std::uint64_t, kRefusalCount> refused{};     // the supervisor's refusals, by Refusal; [none] = 0
  std::uint64_t excitations_refused = 0;  // by the operator thread's checks (excitation_gate.hpp)
  std::uint64_t resets_refused = 0;       // by the operator thread: the drivers did not recover
  std::uint64_t gains_refused = 0;        // GAINS the law refused
};

}  // namespace hsa::daemon
