#include "daemon/hsad/daemon_cycle.hpp"

#include <algorithm>
#include <iterator>

#include "drivers/clock.hpp"

namespace hsa::daemon {
namespace {

std::int32_t clamp32(std::int64_t v) noexcept {
  return static_cast<std::int32_t>(std::clamp<std::int64_t>(v, 0, INT32_MAX));
}


// `epoch_ns` turns the cycle's time (from the daemon's start) back into CLOCK_MONOTONIC, the clock
// telemetry_t.utime is documented in and senders stamp setpoints with.
TelemetrySample telemetry_sample(const AxisTelemetry& a, std::int64_t epoch_ns, std::uint64_t tick,
                                 const CycleTimingStats& t) noexcept {
  TelemetrySample s;
  s.utime = (epoch_ns + a.t_ns) / 1000;
  s.tick = tick;
  s.position_m = a.position_m;
  s.velocity_m_s = a.velocity_m_s;
  s.pressure_a_pa = a.pressure_a_pa;
  s.pressure_b_pa = a.pressure_b_pa;
  s.load_pressure_pa = a.pressure_load_pa;
  s.spool_position_m = a.spool_position_m;
  s.setpoint_m = a.mode == ControlMode::position ? a.setpoint : 0.0;
  s.following_error_m = a.following_error_m;
  s.valve_opening = a.opening;
  s.current_ref_a = a.command;
  s.valve_enabled = a.valve_enabled;
  s.setpoint_utime = a.setpoint_utime;
  s.state = a.state;
  s.holding = a.holding;
  s.exciting = a.exciting;
  s.lateness_ns = t.lateness_ns;
  s.lateness_max_ns = t.lateness_max_ns;
  s.exec_time_ns = t.exec_ns;
  s.exec_time_max_ns = t.exec_max_ns;
  s.overruns = t.overruns;
  std::copy(std::begin(a.inputs), std::end(a.inputs), std::begin(s.inputs));
  s.estop = a.estop;
  return s;
}

}  // namespace

DaemonCycle::DaemonCycle(DriverSet& drivers, std::vector<std::unique_ptr<AxisRuntime>>& axes,
                         SystemdWatchdog& watchdog)
    : drivers_(drivers),
      axes_(axes),
      watchdog_(watchdog),
      epoch_ns_(io::monotonic_ns()) {}

void DaemonCycle::cycle(const CycleTiming& timing) noexcept {
  const std::int64_t t_ns = timing.woke_ns - epoch_ns_;
  const io::Duration dt{last_ns_ == 0 ? timing.period_ns : t_ns - last_ns_};
  last_ns_ = t_ns;

  timing_.lateness_ns = clamp32(timing.woke_ns - timing.scheduled_ns);
  timing_.lateness_max_ns = std::max(timing_.lateness_max_ns, timing_.lateness_ns);
  if (timing.skipped > 0) timing_.overruns += static_cast<std::int64_t>(timing.skipped);
  skipped_ = timing.skipped;

  // A driver whose read or write failed stays in its error state (and keeps failing) until it is
  // recovered, so the mask of this cycle's read and the last write is enough.
  const std::uint64_t read_failed = drivers_.read_all(io::Timestamp{t_ns}, dt);
  const std::uint64_t failed = read_failed | failed_writes_;
  run_axes(t_ns, timing.tick, failed, static_cast<std::uint32_t>(timing.overrun_streak));
  failed_writes_ = drivers_.write_all(io::Timestamp{t_ns}, dt);
  // A driver in error fails its read every cycle until it is recovered, so this mask holds it
  // for as long as it is out; a driver new in it gets its make_safe now, in its failing cycle.
  const std::uint64_t out = read_failed | failed_writes_;
  drivers_.make_safe(out & ~made_safe_);
  made_safe_ = out;
  watchdog_.heartbeat(timing.woke_ns);

  timing_.exec_ns = clamp32(io::monotonic_ns() - timing.woke_ns);
  timing_.exec_max_ns = std::max(timing_.exec_max_ns, timing_.exec_ns);
  // The flight recorder's rows of this cycle are complete now that its execution time is known.
  for (auto& axis : axes_) {
    if (axis->recorder) axis->recorder->commit(timing_.exec_ns);
  }
}

void DaemonCycle::run_axes(std::int64_t t_ns, std::uint64_t tick, std::uint64_t failed_drivers,
                           std::uint32_t streak) noexcept {
  for (auto& axis_ptr : axes_) {
    AxisRuntime& axis = *axis_ptr;
    const bool publish_telemetry = axis.telemetry.take(tick);
    const bool open_loop = axis.loop->telemetry().mode == ControlMode::open_loop;

    // Only the newest setpoint matters; each one gets a sequence number of the daemon's own, so
    // two senders that both count from 1 are still seen as new setpoints.
    // A streamed setpoint is a position: in open loop the opening comes with the MODE command.
    SetpointInput sp;
    bool fresh = false;
    while (axis.port.pop_setpoint(sp)) fresh = true;
    if (fresh && !open_loop) {
      sp.seq = axis.op.setpoint.seq + 1;
      axis.op.setpoint = sp;
    }
    // One command per cycle, each answered in the cycle that handles it. A CAPTURE is the flight
    // recorder's: before the loop runs, so that a capture "now" has this cycle's row as its trigger.
    const bool took_command = axis.port.pop_axis_command(command_);
    const bool capture = took_command && command_.kind == CommandKind::capture;
    CommandOutcome captured{};
    if (capture) {
      captured = {command_.seq, command_.ticket, CommandKind::capture, axis.recorder != nullptr,
                  axis.recorder ? Refusal::none : Refusal::no_recorder, FaultReason::none};
      if (axis.recorder) axis.recorder->apply(command_.capture, command_.ticket);
    } else if (took_command) {
      command_.seq = axis.op.command.seq + 1;
      axis.op.command = command_;
    }

    const ExecutiveInputs executive{streak, (failed_drivers & axis.driver_mask) != 0};
    axis.loop->cycle(t_ns, axis.op, executive, tick);
    if (axis.recorder) axis.recorder->record(*axis.loop, tick, skipped_, timing_.lateness_ns);
    const AxisTelemetry& tm = axis.loop->telemetry();
    if (took_command) (void)axis.port.push_answer(capture ? captured : tm.last_command);
    if (publish_telemetry) axis.port.push_telemetry(telemetry_sample(tm, epoch_ns_, tick, timing_));
    axis.port.publish_latest(tm);
  }
}

void DaemonCycle::drive_safe(std::int64_t t_ns) noexcept {
  const std::int64_t t = t_ns - epoch_ns_;
  for (auto& axis : axes_) {
    AxisCommand disable;
    disable.seq = axis->op.command.seq + 1;
    disable.kind = CommandKind::disable;
    axis->op.command = disable;
    axis->loop->cycle(t, axis->op, ExecutiveInputs{.final_cycle = true});
    axis->port.publish_latest(axis->loop->telemetry());
  }
  (void)drivers_.write_all(io::Timestamp{t}, io::Duration{0});
  drivers_.make_safe(~std::uint64_t{0});
}

}  // namespace hsa::daemon
