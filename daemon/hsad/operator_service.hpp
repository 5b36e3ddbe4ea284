// The operator's side of hsad, on a normal thread: it takes each axis's commands from its port and
// passes them on to the RT thread as they are, except what must not reach it (gain changes, which
// the law checks here and AxisLoop::request_gains hands over at a cycle boundary; a reset, which
// recovers the axis's drivers first); it takes the axis's answer to each command for its sender;
// and it composes status from each axis's latest telemetry and the executive's counters. Fault
// and refusal texts are formatted here, never on the RT thread. A CAPTURE command is checked and
// resolved against the axis's recorder ring here (capture_gate.hpp) before it goes on.
//
// A reset of an axis whose drivers failed recovers them first, here: the RT thread never runs a
// lifecycle step (DriverSet::recover). The reset reaches the RT thread only after a telemetry
// sample of a later cycle shows no persistent condition (fault_kind::persistent), so the
// supervisor judges it on a cycle that read and wrote the recovered drivers, once their inputs
// had the time to arrive. When a condition other than the driver error stays for
// kResetWaitPolls polls, the reset goes on and the supervisor refuses it naming that cause. When
// recovery fails, or the drivers fail again (their reason is given), or the driver error stays,
// the reset is refused here. A refused reset changes nothing: the latched fault and its text stay
// as they were, the refusal is its sender's result in status, and the next reset tries again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "daemon/hsad/axis_health_counts.hpp"
#include "daemon/hsad/command_results.hpp"
#include "daemon/hsad/metrics_text.hpp"
#include "daemon/axis/axis_runtime.hpp"
#include "daemon/hsad/driver_set.hpp"
#include "daemon/rt/realtime_grant.hpp"
#include "daemon/rt/rt_config.hpp"
#include "daemon/rt/rt_executive.hpp"
#include "daemon/recorder/capture_writer.hpp"

namespace hsa::daemon {

class OperatorService {
 public:
  OperatorService(std::vector<std::unique_ptr<AxisRuntime>>& axes, DriverSet& drivers,
                  const RtExecutive& executive, const RtConfig& rt, const RealtimeGrant& grant);

  void poll();  // commands in, status out; call at ~100 Hz

  // The flight recorder's writer, whose counts (files written, write failures) status carries;
  // without one they are 0.
  void attach_recorder(const CaptureWriter* writer) { writer_ = writer; }
  // The condition armed on the axis's recorder, as status says it ("" none).
  [[nodiscard]] std::string armed_condition(std::size_t axis) const;

  // What a command from LCM does (poll() calls it for each one the axis's port holds).
  void handle_command(std::size_t axis, OperatorCommand command);
  // What a RESET command from LCM does (poll() calls it for each one): recovers the axis's failed
  // drivers and forwards the reset to the RT thread now or, after a recovery, from a later poll.
  void request_reset(std::size_t axis, const CommandSender& from = {});
  // Why the axis's last reset was refused here (empty: not refused, or the fault has cleared);
  // also its sender's result in status.
  [[nodiscard]] const std::string& reset_refusal(std::size_t axis) const { return resets_[axis].refusal; }

  // The axis's status as poll() would publish it now.
  [[nodiscard]] StatusSample status(std::size_t axis) const { return status_of(axis, executive_.snapshot()); }

  [[nodiscard]] std::uint64_t gain_changes_refused() const { return gains_refused_; }
  // Why the axis's last GAINS command was refused (empty: none was).
  [[nodiscard]] const std::string& gains_refusal(std::size_t axis) const { return gains_refusals_[axis]; }
  // The device's reason for the axis's latched driver-error fault ("'rig': write failed: Modbus
  // exception 3 ..."), taken when the fault first showed; empty when there is none.
  [[nodiscard]] const std::string& driver_failure(std::size_t axis) const { return driver_failures_[axis]; }
  // The answers to the axis's most recent operator commands, oldest first, as status carries them.
  [[nodiscard]] const std::deque<CommandResults::Result>& command_results(std::size_t axis) const {
    return results_[axis].recent();
  }
  // What this thread counted of the axis (faults latched, refusals), for the metrics.
  [[nodiscard]] const AxisHealthCounts& health_counts(std::size_t axis) const { return counts_[axis]; }
  // The metrics (metrics_text.hpp) of what this thread sees: the executive's statistics, every
  // axis's state, counts and port counters, every driver's health. The caller adds the recorder's
  // counters and the daemon's own (system, version, start time).
  [[nodiscard]] MetricsSnapshot metrics_snapshot() const;

 private:
  // Polls (at ~100 Hz) a reset waits for a clean cycle after its drivers were recovered: 1 s.
  static constexpr int kResetWaitPolls = 100;

  // A reset that waits for its axis's recovered drivers to run a clean cycle.
  struct ResetGate {
    bool pending = false;
    std::uint64_t after_cycle = 0;  // forward once a sample of a later cycle is clean
    int polls_left = 0;
    std::string refusal;  // why the last reset was refused here
    CommandSender from;  // whose reset waits
  };

  void handle_commands(std::size_t index);
  void handle_capture(std::size_t index, OperatorCommand& c);
  void advance_reset(std::size_t index);
  void refuse_reset(std::size_t index, std::string why);
  void forward(AxisRuntime& axis, const AxisCommand& command);
  void forward_reset(std::size_t index);  // with a ticket for whoever asked
  [[nodiscard]] StatusSample status_of(std::size_t index, const RtStats& rt) const;
  void note_driver_failure(std::size_t index);
  void count_fault(std::size_t index);  // a newly latched fault in the latest telemetry
  // Why an input of the axis may be missing, from its drivers (each "" when nothing says).
  struct InputTrouble {
    // The first driver whose link is down or whose device does not answer ("driver 'io' link
    // down: ...: Connection refused", "driver 'io' not answering: ...: Connection timed out").
    std::string link;
    // The first driver with a last error, its link up or not ("driver 'io': ...: Modbus
    // exception 2 (Illegal data address) reading discrete inputs 100..100").
    std::string error;
  };
  // The axis's drivers into `s` (state, link, last error, counters), and what they say of inputs.
  InputTrouble fill_drivers(std::size_t index, StatusSample& s) const;
  // The axis's refusal in words, with the numbers the supervisor's static text leaves out.
  [[nodiscard]] std::string refusal_text(std::size_t index, const CommandOutcome& outcome) const;

  std::vector<std::unique_ptr<AxisRuntime>>& axes_;
  DriverSet& drivers_;
  const RtExecutive& executive_;
  RtConfig rt_;
  RealtimeGrant grant_;
  std::vector<AxisTelemetry> latest_;
  std::vector<ResetGate> resets_;
  std::vector<std::string> gains_refusals_;
  std::vector<std::uint64_t> gains_refused_per_axis_;
  std::vector<std::string> driver_failures_;
  std::vector<CommandResults> results_;
  std::vector<AxisHealthCounts> counts_;
  std::vector<FaultRecord> counted_fault_;  // the latched fault last counted, per axis
  std::uint64_t gains_refused_ = 0;
  const CaptureWriter* writer_ = nullptr;
  // The last condition forwarded to each axis's recorder: its ticket and its words. Status shows
  // them while the recorder says that ticket is armed (AxisRecorder::armed_ticket).
  struct ArmedCondition {
    std::uint64_t ticket = 0;
    std::string text;
  };
  std::vector<ArmedCondition> conditions_;
};

}  // namespace hsa::daemon
