#include "daemon/hsad/operator_service.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "daemon/hsad/capture_gate.hpp"
#include "daemon/hsad/excitation_gate.hpp"
#include "daemon/recorder/capture_condition.hpp"

namespace hsa::daemon {
namespace {

// Conditions that outlive the cycles after a recovery: while one is present, a reset waits.
constexpr std::uint32_t kPersistentFaults = fault_mask(fault_kind::persistent);

}  // namespace

OperatorService::OperatorService(std::vector<std::unique_ptr<AxisRuntime>>& axes, DriverSet& drivers,
                                 const RtExecutive& executive, const RtConfig& rt, const RealtimeGrant& grant)
    : axes_(axes),
      drivers_(drivers),
      executive_(executive),
      rt_(rt),
      grant_(grant),
      latest_(axes.size()),
      resets_(axes.size()),
      gains_refusals_(axes.size()),
      gains_refused_per_axis_(axes.size(), 0),
      driver_failures_(axes.size()),
      results_(axes.size()),
      counts_(axes.size()),
      counted_fault_(axes.size()),
      conditions_(axes.size()) {}

// The one place the two spellings of a link's state meet.
static_assert(static_cast<int>(DriverEntry::Link::none) == static_cast<int>(io::DriverHealth::Link::none));
static_assert(static_cast<int>(DriverEntry::Link::up) == static_cast<int>(io::DriverHealth::Link::up));
static_assert(static_cast<int>(DriverEntry::Link::down) == static_cast<int>(io::DriverHealth::Link::down));
static_assert(static_cast<int>(DriverEntry::Link::not_answering) ==
              static_cast<int>(io::DriverHealth::Link::not_answering));

void OperatorService::note_driver_failure(std::size_t index) {
  const AxisTelemetry& tm = latest_[index];
  if (tm.fault.reason != FaultReason::driver_error) {
    driver_failures_[index].clear();  // the reason belongs to the fault: it goes when it does
    return;
  }
  if (!driver_failures_[index].empty()) return;  // the first reason is the cause
  driver_failures_[index] = drivers_.failures_of(axes_[index]->driver_mask);
  if (!driver_failures_[index].empty()) {
    std::fprintf(stderr, "hsad: axis %s: driver error: %s\n", axes_[index]->port.name().c_str(),
                 driver_failures_[index].c_str());
  }
}

void OperatorService::count_fault(std::size_t index) {
  const FaultRecord& latched = latest_[index].fault;
  FaultRecord& counted = counted_fault_[index];
  if (latched.reason == FaultReason::none) {
    counted = {};
    return;
  }
  // The trip time tells a new latch of the same reason from the one already counted.
  if (latched.reason == counted.reason && latched.t_ns == counted.t_ns) return;
  ++counts_[index].faults[static_cast<std::size_t>(latched.reason)];
  counted = latched;
}

void OperatorService::forward_reset(std::size_t index) {
  AxisCommand reset;
  reset.kind = CommandKind::reset;
  reset.ticket = results_[index].issue(resets_[index].from);
  forward(*axes_[index], reset);
}

void OperatorService::forward(AxisRuntime& axis, const AxisCommand& command) {
  if (!axis.port.push_axis_command(command))
    std::fprintf(stderr, "hsad: axis %s: command ring full, command dropped\n", axis.port.name().c_str());
}

void OperatorService::handle_commands(std::size_t index) {
  OperatorCommand c;
  while (axes_[index]->port.pop_command(c)) handle_command(index, c);
}

void OperatorService::handle_command(std::size_t index, OperatorCommand c) {
  AxisRuntime& axis = *axes_[index];
  switch (c.command.kind) {
    case CommandKind::reset:
      request_reset(index, c.from);  // forwarded now, or once the recovered drivers ran a clean cycle
      break;
    case CommandKind::gains:
      try {
        axis.loop->request_gains(c.command.gains);
        results_[index].decide(c.from, true, {});
      } catch (const std::exception& e) {
        ++gains_refused_;
        ++gains_refused_per_axis_[index];
        ++counts_[index].gains_refused;
        gains_refusals_[index] = e.what();
        results_[index].decide(c.from, false, e.what());
        std::fprintf(stderr, "hsad: axis %s: gains refused: %s\n", axis.port.name().c_str(), e.what());
      }
      break;
    case CommandKind::excite:
      // Its limits, speed and stability are judged here, off the RT thread (excitation_gate.hpp).
      if (c.command.excite.at_rod) c.command.excite.working_point_m = latest_[index].position_m;
      if (std::string why = excitation_gate::refusal(c.command.excite, axis.loop->supervisor().params(),
                                                     latest_[index].position_m);
          !why.empty()) {
        results_[index].decide(c.from, false, why);
        ++counts_[index].excitations_refused;
        std::fprintf(stderr, "hsad: axis %s: excitation refused: %s\n", axis.port.name().c_str(), why.c_str());
        break;
      }
      c.command.ticket = results_[index].issue(c.from);
      forward(axis, c.command);
      break;
    case CommandKind::capture:
      handle_capture(index, c);
      break;
    default:
      c.command.ticket = results_[index].issue(c.from);
      forward(axis, c.command);
      break;
  }
}

void OperatorService::handle_capture(std::size_t index, OperatorCommand& c) {
  AxisRuntime& axis = *axes_[index];
  if (!axis.recorder) {
    results_[index].decide(c.from, false, std::string(to_string(Refusal::no_recorder)));
    return;
  }
  const CaptureRing& ring = axis.recorder->ring();
  const CaptureRingShape shape{ring.capacity(), ring.post_rows(), 1e9 / static_cast<double>(rt_.period.count())};
  CaptureRequest& request = c.command.capture;
  if (std::string why = capture_gate::resolve(request, shape); !why.empty()) {
    results_[index].decide(c.from, false, why);
    std::fprintf(stderr, "hsad: axis %s: capture refused: %s\n", axis.port.name().c_str(), why.c_str());
    return;
  }
  c.command.ticket = results_[index].issue(c.from);
  const double rate = shape.rate_hz;
  if (request.action == CaptureAction::arm) {
    const ConditionSpec spec{request.signal_index, request.crossing, request.level, request.repeat};
    char lengths[96];
    std::snprintf(lengths, sizeof lengths, ", %.3g s before, %.3g s after", request.pre_rows / rate,
                  request.post_rows / rate);
    conditions_[index] = {c.command.ticket, describe(spec) + (request.repeat ? " (repeat" : " (single") + lengths + ")"};
    std::fprintf(stderr, "hsad: axis %s: flight recorder armed: %s\n", axis.port.name().c_str(),
                 conditions_[index].text.c_str());
  } else if (request.action == CaptureAction::disarm) {
    std::fprintf(stderr, "hsad: axis %s: flight recorder disarmed\n", axis.port.name().c_str());
  }
  forward(axis, c.command);
}

std::string OperatorService::armed_condition(std::size_t index) const {
  const AxisRuntime& axis = *axes_[index];
  const ArmedCondition& armed = conditions_[index];
  if (!axis.recorder || armed.ticket == 0 || axis.recorder->armed_ticket() != armed.ticket) return "";
  return armed.text;
}

void OperatorService::request_reset(std::size_t index, const CommandSender& from) {
  AxisRuntime& axis = *axes_[index];
  ResetGate& gate = resets_[index];
  gate.refusal.clear();
  gate.from = from;
  const std::uint64_t failed = drivers_.out_of_cycle(axis.driver_mask);
  const bool driver_error_seen = (latest_[index].active_faults & fault_bit(FaultReason::driver_error)) != 0;
  if (failed == 0 && !driver_error_seen) {
    gate.pending = false;
    forward_reset(index);
    return;
  }
  if (failed != 0) {
    if (const io::Result r = drivers_.recover(failed); !r) {
      refuse_reset(index, r.message());
      return;
    }
    std::fprintf(stderr, "hsad: axis %s: driver %s recovered; the reset waits for a clean cycle\n",
                 axis.port.name().c_str(), drivers_.names_of(failed).c_str());
  }
  // Every sample of a cycle after the newest one now was taken with the drivers back in the RT
  // cycle; the first of them without a persistent condition lets the reset through.
  if (const AxisTelemetry* tm = axis.port.take_latest()) latest_[index] = *tm;
  gate.pending = true;
  gate.after_cycle = latest_[index].cycle;
  gate.polls_left = kResetWaitPolls;
}

void OperatorService::advance_reset(std::size_t index) {
  ResetGate& gate = resets_[index];
  if (!gate.pending) return;
  AxisRuntime& axis = *axes_[index];
  const AxisTelemetry& tm = latest_[index];
  const bool later = tm.cycle > gate.after_cycle;
  if (const std::uint64_t failed = drivers_.out_of_cycle(axis.driver_mask); failed != 0) {
    // The standing cause is the driver's own reason, as it failed this time.
    refuse_reset(index, "driver " + drivers_.names_of(failed) + " failed again right after its recovery (" +
                            drivers_.failures_of(failed) + ")");
  } else if (later && (tm.active_faults & kPersistentFaults) == 0) {
    gate.pending = false;
    forward_reset(index);
  } else if (--gate.polls_left <= 0) {
    if (!later || (tm.active_faults & fault_bit(FaultReason::driver_error)) != 0) {
      refuse_reset(index, "the recovered drivers ran no clean cycle within 1 s");
    } else {
      // A cause other than the drivers stands (an input the recovered bus still cannot read, a
      // pressed e-stop): the supervisor refuses the reset and names it.
      gate.pending = false;
      forward_reset(index);
    }
  }
}

void OperatorService::refuse_reset(std::size_t index, std::string why) {
  ResetGate& gate = resets_[index];
  gate.pending = false;
  gate.refusal = std::move(why);
  ++counts_[index].resets_refused;
  // The refusal's own words: hsactl says "reset refused: " itself.
  results_[index].decide(gate.from, false, gate.refusal);
  std::fprintf(stderr, "hsad: axis %s: reset refused: %s\n", axes_[index]->port.name().c_str(),
               gate.refusal.c_str());
}

StatusSample OperatorService::status_of(std::size_t index, const RtStats& rt) const {
  const AxisTelemetry& tm = latest_[index];
  const std::string& driver_failure = driver_failures_[index];
  StatusSample s;
  const InputTrouble trouble = fill_drivers(index, s);
  s.utime = tm.t_ns / 1000;
  s.state = tm.state;
  s.mode = tm.mode;
  s.holding = tm.holding;
  s.exciting = tm.exciting;
  if (tm.fault.reason != FaultReason::none) {
    s.fault = tm.fault.reason;
    std::string text = describe(tm.fault);
    if (tm.fault.reason == FaultReason::driver_error && !driver_failure.empty()) text += " (" + driver_failure + ")";
    // An input that went stale or silent because its bus is down or its device silent: say which
    // bus and why. An input that never arrived may also have been refused (an exception answer).
    const bool input_fault = tm.fault.reason == FaultReason::sensor_not_ok || tm.fault.reason == FaultReason::estop ||
                             tm.fault.reason == FaultReason::encoder_stale ||
                             tm.fault.reason == FaultReason::inputs_not_ready;
    const std::string& why = !trouble.link.empty() || tm.fault.reason != FaultReason::inputs_not_ready
                                 ? trouble.link
                                 : trouble.error;
    if (input_fault && !why.empty()) text += " (" + why + ")";
    std::snprintf(s.fault_text, sizeof s.fault_text, "%s", text.c_str());
  }
  s.rt_overruns = static_cast<std::int64_t>(rt.overruns);
  // Not counted is not zero: without the counting hooks the status says so (-1).
  s.rt_allocations = rt.counters_linked ? static_cast<std::int64_t>(rt.steady_allocations) : -1;
  s.rt_locks = rt.counters_linked ? static_cast<std::int64_t>(rt.steady_locks) : -1;
  s.rt_minor_faults = static_cast<std::int64_t>(rt.steady_minor_faults);
  s.rt_major_faults = static_cast<std::int64_t>(rt.steady_major_faults);
  s.sched_fifo = grant_.sched_fifo;
  s.memory_locked = grant_.memory_locked;
  s.rt_priority = static_cast<std::int16_t>(grant_.sched_fifo ? rt_.priority : 0);
  s.rt_cpu = static_cast<std::int16_t>(grant_.affinity ? rt_.cpu : -1);
  s.kp = tm.kp;
  s.ki = tm.ki;
  s.gain_changes_applied = static_cast<std::int64_t>(tm.param_changes_applied);
  s.gain_changes_refused = static_cast<std::int64_t>(gains_refused_per_axis_[index]);
  std::snprintf(s.gains_refusal, sizeof s.gains_refusal, "%s", gains_refusals_[index].c_str());
  if (const AxisRecorder* recorder = axes_[index]->recorder.get()) {
    const CaptureRingCounts ring = recorder->ring().counts();
    s.capture_triggers_merged = static_cast<std::int64_t>(ring.merged);
    s.capture_triggers_dropped = static_cast<std::int64_t>(ring.dropped);
    if (writer_ != nullptr) {
      const RecorderCounters written = writer_->counters(index);
      s.captures_written = static_cast<std::int64_t>(written.written);
      s.capture_write_failures = static_cast<std::int64_t>(written.failed);
    }
    std::snprintf(s.capture_condition, sizeof s.capture_condition, "%s", armed_condition(index).c_str());
  }
  results_[index].fill(s);
  return s;
}

OperatorService::InputTrouble OperatorService::fill_drivers(std::size_t index, StatusSample& s) const {
  InputTrouble trouble;
  const std::vector<io::DriverHandle*> handles = drivers_.handles();
  for (std::size_t i = 0; i < handles.size() && s.num_drivers < StatusSample::kMaxDrivers; ++i) {
    if ((axes_[index]->driver_mask & (std::uint64_t{1} << i)) == 0) continue;
    const io::DriverHandle& d = *handles[i];
    const io::DriverHealth health = d.health();
    DriverEntry& e = s.drivers[s.num_drivers++];
    std::snprintf(e.name, sizeof e.name, "%s", d.name().c_str());
    std::snprintf(e.plugin, sizeof e.plugin, "%s", d.plugin().name().c_str());
    std::snprintf(e.state, sizeof e.state, "%s", std::string(io::to_string(d.state())).c_str());
    std::snprintf(e.failure, sizeof e.failure, "%s", d.failure_reason().c_str());
    e.link = static_cast<DriverEntry::Link>(health.link);
    std::snprintf(e.last_error, sizeof e.last_error, "%s", health.last_error.c_str());
    for (const auto& [name, value] : health.counters) {
      if (e.num_counters == DriverEntry::kMaxCounters) break;
      std::snprintf(e.counter_name[e.num_counters], DriverEntry::kNameSize, "%s", name.c_str());
      e.counter_value[e.num_counters++] = static_cast<std::int64_t>(value);
    }
    const std::string last_error = health.last_error.empty() ? "" : ": " + health.last_error;
    const bool silent = health.link == io::DriverHealth::Link::down || health.link == io::DriverHealth::Link::not_answering;
    if (silent && trouble.link.empty()) {
      trouble.link = "driver '" + d.name() + "' " +
                     (health.link == io::DriverHealth::Link::down ? "link down" : "not answering") + last_error;
    }
    if (!last_error.empty() && trouble.error.empty()) trouble.error = "driver '" + d.name() + "'" + last_error;
  }
  return trouble;
}

std::string OperatorService::refusal_text(std::size_t index, const CommandOutcome& outcome) const {
  std::string text(to_string(outcome.refusal));
  const SupervisorParams& p = axes_[index]->loop->supervisor().params();
  char numbers[96];
  switch (outcome.refusal) {
    case Refusal::cause_present:
      text += ": " + std::string(summary(outcome.blocking));
      break;
    case Refusal::excitation_outside_limits:
    case Refusal::target_outside_limits:
      std::snprintf(numbers, sizeof numbers, " [%.2f, %.2f] mm", p.soft_limit_low_m * 1e3, p.soft_limit_high_m * 1e3);
      text += numbers;
      break;
    case Refusal::speed_over_limit:
      std::snprintf(numbers, sizeof numbers, " (%.1f mm/s)", p.max_speed_m_s * 1e3);
      text += numbers;
      break;
    case Refusal::accel_over_limit:
      std::snprintf(numbers, sizeof numbers, " (%.3g m/s²)", move_bounds(p).accel_m_s2);
      text += numbers;
      break;
    // The plant set's figure for the direction the move travelled (SupervisorParams::capability).
    case Refusal::speed_over_extend_capability:
    case Refusal::speed_over_retract_capability: {
      const Travel t = outcome.refusal == Refusal::speed_over_extend_capability ? Travel::extend : Travel::retract;
      std::snprintf(numbers, sizeof numbers, " (%.1f mm/s)", p.capability.of(t).speed_m_s * 1e3);
      text += numbers;
      break;
    }
    case Refusal::accel_over_extend_capability:
    case Refusal::accel_over_retract_capability: {
      const Travel t = outcome.refusal == Refusal::accel_over_extend_capability ? Travel::extend : Travel::retract;
      std::snprintf(numbers, sizeof numbers, " (%.3g m/s²)", p.capability.of(t).accel_m_s2);
      text += numbers;
      break;
    }
    default: break;
  }
  return text;
}

void OperatorService::poll() {
  const RtStats rt = executive_.snapshot();
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    AxisRuntime& axis = *axes_[i];
    if (const AxisTelemetry* tm = axis.port.take_latest()) latest_[i] = *tm;
    CommandOutcome outcome;
    while (axis.port.pop_answer(outcome)) {
      const auto refusal = static_cast<std::size_t>(outcome.refusal);
      if (!outcome.accepted && refusal < kRefusalCount) ++counts_[i].refused[refusal];
      results_[i].answer(outcome, refusal_text(i, outcome));
    }
    count_fault(i);
    note_driver_failure(i);  // before a reset recovers the driver and its reason is gone
    handle_commands(i);
    advance_reset(i);
    // A refusal belongs to the fault it kept latched: it goes when the fault does.
    if (latest_[i].fault.reason == FaultReason::none) resets_[i].refusal.clear();
    (void)axis.port.push_status(status_of(i, rt));
  }
}

MetricsSnapshot OperatorService::metrics_snapshot() const {
  MetricsSnapshot m;
  m.period_ns = rt_.period.count();
  m.grant = grant_;
  m.rt = executive_.snapshot();
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    AxisMetrics& a = m.axes.emplace_back();
    a.name = axes_[i]->port.name();
    a.state = latest_[i].state;
    a.latched = latest_[i].fault.reason;
    a.health = counts_[i];
    a.port = axes_[i]->port.counters();
    a.gain_changes_applied = latest_[i].param_changes_applied;
  }
  for (const io::DriverHandle* d : drivers_.handles()) {
    m.drivers.push_back({d->name(), d->plugin().name(), std::string(io::to_string(d->state())), d->health()});
  }
  return m;
}

}  // namespace hsa::daemon
