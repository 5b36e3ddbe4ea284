#include "daemon/hsad/metrics_text.hpp"

#include <string_view>

#include "daemon/axis/reject_reason.hpp"
#include "daemon/hsad/prometheus_text.hpp"
#include "drivers/driver_handle.hpp"

namespace hsa::daemon {
namespace {

using Type = PrometheusText::Type;

constexpr AxisState kAxisStates[] = {AxisState::init, AxisState::disabled, AxisState::enabled, AxisState::fault,
                                     AxisState::estop};
constexpr io::DriverState kDriverStates[] = {io::DriverState::unconfigured, io::DriverState::inactive,
                                             io::DriverState::active, io::DriverState::error,
                                             io::DriverState::finalized};
constexpr io::DriverHealth::Link kLinks[] = {io::DriverHealth::Link::none, io::DriverHealth::Link::up,
                                             io::DriverHealth::Link::down, io::DriverHealth::Link::not_answering};

// A link's state as a label value: to_string's words, with '_' for the space.
std::string_view link_id(io::DriverHealth::Link link) {
  return link == io::DriverHealth::Link::not_answering ? "not_answering" : io::to_string(link);
}

double seconds(std::int64_t ns) { return static_cast<double>(ns) / 1e9; }  // 5000 ns reads "5e-06"

void lateness_histogram(PrometheusText& out, const LatencyHistogram::Counts& counts) {
  out.family("hsa_rt_lateness_seconds", Type::histogram,
             "RT thread wake-up lateness (woke - scheduled), every cycle since hsad started; _sum from the "
             "1 us bins' lower edges");
  std::uint64_t cumulative = 0;
  std::uint64_t total = 0;
  double sum_s = 0.0;
  for (std::size_t b = 0; b < counts.size(); ++b) {
    total += counts[b];
    sum_s += static_cast<double>(counts[b]) * seconds(LatencyHistogram::lower_edge_ns(b));
  }
  std::size_t b = 0;
  for (const std::int64_t le : kLatenessBucketsNs) {
    // Every bin below `le`: a bin [lower, upper) with upper <= le holds only values < le.
    while (b < LatencyHistogram::kOverflowBin && LatencyHistogram::upper_edge_ns(b) <= le) cumulative += counts[b++];
    out.sample({{"le", PrometheusText::format_double(seconds(le))}}, cumulative, "_bucket");
  }
  out.sample({{"le", "+Inf"}}, total, "_bucket");
  out.sample({}, sum_s, "_sum");
  out.sample({}, total, "_count");
}

void daemon_families(PrometheusText& out, const MetricsSnapshot& s) {
  out.family("hsa_running", Type::gauge, "1 while hsad runs; 0 in the file hsad writes as it stops");
  out.sample({}, s.running ? 1.0 : 0.0);
  out.family("hsa_info", Type::gauge, "hsad's system name and version, as labels; always 1");
  out.sample({{"system", s.system}, {"version", s.version}}, 1.0);
  out.family("hsa_start_time_seconds", Type::gauge, "Unix time hsad started");
  out.sample({}, s.start_time_s);
  out.family("hsa_rt_sched_fifo", Type::gauge, "1 when the RT thread got SCHED_FIFO");
  out.sample({}, s.grant.sched_fifo ? 1.0 : 0.0);
  out.family("hsa_rt_memory_locked", Type::gauge, "1 when mlockall succeeded");
  out.sample({}, s.grant.memory_locked ? 1.0 : 0.0);
  out.family("hsa_rt_period_seconds", Type::gauge, "the RT thread's base period");
  out.sample({}, seconds(s.period_ns));
  out.family("hsa_rt_cycles_total", Type::counter, "RT cycles run (one thread serves every axis)");
  out.sample({}, s.rt.cycles);
  out.family("hsa_rt_overruns_total", Type::counter, "RT cycles that ended after their next deadline");
  out.sample({}, s.rt.overruns);
  out.family("hsa_rt_skipped_periods_total", Type::counter, "RT periods skipped after overruns");
  out.sample({}, s.rt.skipped_periods);
  out.family("hsa_rt_overrun_streak_max", Type::gauge, "longest streak of consecutive RT overruns since start");
  out.sample({}, s.rt.max_overrun_streak);
  lateness_histogram(out, s.rt.lateness_histogram);
  out.family("hsa_rt_lateness_max_seconds", Type::gauge, "largest RT wake-up lateness since start");
  out.sample({}, seconds(s.rt.max_lateness_ns));
  out.family("hsa_rt_execution_max_seconds", Type::gauge, "longest RT cycle (wake-up to end of work) since start");
  out.sample({}, seconds(s.rt.max_execution_ns));
}

void axis_families(PrometheusText& out, const std::vector<AxisMetrics>& axes) {
  using Counter = std::uint64_t;
  auto per_axis = [&](std::string_view name, Type type, std::string_view help, auto value) {
    out.family(name, type, help);
    for (const AxisMetrics& a : axes) out.sample({{"axis", a.name}}, static_cast<Counter>(value(a)));
  };

  out.family("hsa_axis_state", Type::gauge, "1 for the axis's state (status words), 0 for the others");
  for (const AxisMetrics& a : axes) {
    for (const AxisState st : kAxisStates) {
      out.sample({{"axis", a.name}, {"state", std::string(to_string(st))}}, a.state == st ? 1.0 : 0.0);
    }
  }
  out.family("hsa_axis_fault_latched", Type::gauge, "1 for the reason of the axis's latched fault, 0 for the others");
  for (const AxisMetrics& a : axes) {
    for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
      const auto reason = static_cast<FaultReason>(r);
      out.sample({{"axis", a.name}, {"reason", std::string(to_string(reason))}}, a.latched == reason ? 1.0 : 0.0);
    }
  }
  out.family("hsa_faults_total", Type::counter, "faults latched, by reason");
  for (const AxisMetrics& a : axes) {
    for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
      out.sample({{"axis", a.name}, {"reason", std::string(to_string(static_cast<FaultReason>(r)))}},
                 a.health.faults[r]);
    }
  }
  out.family("hsa_commands_refused_total", Type::counter,
             "operator commands the axis refused, by reason (the supervisor's, and excitation_checks and "
             "reset_recovery of the operator thread)");
  for (const AxisMetrics& a : axes) {
    for (std::size_t r = 1; r < kRefusalCount; ++r) {
      out.sample({{"axis", a.name}, {"reason", std::string(refusal_id(static_cast<Refusal>(r)))}},
                 a.health.refused[r]);
    }
    out.sample({{"axis", a.name}, {"reason", "excitation_checks"}}, a.health.excitations_refused);
    out.sample({{"axis", a.name}, {"reason", "reset_recovery"}}, a.health.resets_refused);
  }
  out.family("hsa_messages_rejected_total", Type::counter,
             "LCM setpoints and commands refused before they reached the axis, by reason (validation, "
             "authentication, the command lease)");
  for (const AxisMetrics& a : axes) {
    for (std::size_t r = 1; r < kRejectReasonCount; ++r) {
      out.sample({{"axis", a.name}, {"reason", std::string(to_string(static_cast<RejectReason>(r)))}},
                 a.port.rejected[r]);
    }
  }
  per_axis("hsa_gain_changes_refused_total", Type::counter, "GAINS commands the control law refused",
           [](const AxisMetrics& a) { return a.health.gains_refused; });
  per_axis("hsa_gain_changes_applied_total", Type::counter, "gain changes applied at a cycle boundary",
           [](const AxisMetrics& a) { return a.gain_changes_applied; });
  per_axis("hsa_setpoints_accepted_total", Type::counter, "setpoints validated and queued for the RT thread",
           [](const AxisMetrics& a) { return a.port.setpoints_accepted; });
  per_axis("hsa_commands_accepted_total", Type::counter, "commands validated and queued",
           [](const AxisMetrics& a) { return a.port.commands_accepted; });
  per_axis("hsa_lcm_seq_gaps_total", Type::counter, "messages missing from the senders' sequence numbers",
           [](const AxisMetrics& a) { return a.port.lcm_seq_gaps; });
  out.family("hsa_ring_drops_total", Type::counter, "values dropped because a ring between threads was full");
  for (const AxisMetrics& a : axes) {
    out.sample({{"axis", a.name}, {"ring", "setpoint"}}, a.port.setpoint_ring_drops);
    out.sample({{"axis", a.name}, {"ring", "command"}}, a.port.command_ring_drops);
    out.sample({{"axis", a.name}, {"ring", "telemetry"}}, a.port.telemetry_ring_drops);
    out.sample({{"axis", a.name}, {"ring", "status"}}, a.port.status_ring_drops);
  }
  per_axis("hsa_recorder_triggers_total", Type::counter, "flight recorder triggers (faults), merged ones included",
           [](const AxisMetrics& a) { return a.recorder.ring.triggers; });
  per_axis("hsa_recorder_dropped_captures_total", Type::counter,
           "captures given up because the writer held the other buffer",
           [](const AxisMetrics& a) { return a.recorder.ring.dropped; });
  per_axis("hsa_captures_written_total", Type::counter, "capture files written",
           [](const AxisMetrics& a) { return a.recorder.written; });
  per_axis("hsa_capture_write_failures_total", Type::counter, "captures that could not be written",
           [](const AxisMetrics& a) { return a.recorder.failed; });
  per_axis("hsa_captures_deleted_total", Type::counter, "old capture files deleted to keep the folder's bounds",
           [](const AxisMetrics& a) { return a.recorder.deleted; });
  per_axis("hsa_capture_written_bytes_total", Type::counter, "bytes of capture files written",
           [](const AxisMetrics& a) { return a.recorder.bytes; });
}

void driver_families(PrometheusText& out, const std::vector<DriverRunHealth>& drivers) {
  out.family("hsa_driver_state", Type::gauge, "1 for the driver's lifecycle state, 0 for the others");
  for (const DriverRunHealth& d : drivers) {
    for (const io::DriverState st : kDriverStates) {
      const std::string state(io::to_string(st));
      out.sample({{"driver", d.name}, {"plugin", d.plugin}, {"state", state}}, d.state == state ? 1.0 : 0.0);
    }
  }
  out.family("hsa_driver_link", Type::gauge,
             "1 for the state of the driver's link to its device (none: it has no link), 0 for the others");
  for (const DriverRunHealth& d : drivers) {
    for (const io::DriverHealth::Link link : kLinks) {
      out.sample({{"driver", d.name}, {"plugin", d.plugin}, {"link", std::string(link_id(link))}},
                 d.health.link == link ? 1.0 : 0.0);
    }
  }
  out.family("hsa_driver_errors_total", Type::counter, "the driver's error counters, by the driver's name for each");
  for (const DriverRunHealth& d : drivers) {
    for (const auto& [name, value] : d.health.counters) {
      out.sample({{"driver", d.name}, {"plugin", d.plugin}, {"counter", name}}, value);
    }
  }
}

}  // namespace

std::string_view refusal_id(Refusal refusal) noexcept {
  switch (refusal) {
    case Refusal::none: return "none";
    case Refusal::reset_first: return "reset_first";
    case Refusal::estop_active: return "estop_active";
    case Refusal::estop_pressed: return "estop_pressed";
    case Refusal::cause_present: return "cause_present";
    case Refusal::starting: return "starting";
    case Refusal::not_enabled: return "not_enabled";
    case Refusal::not_position_mode: return "not_position_mode";
    case Refusal::target_outside_limits: return "target_outside_limits";
    case Refusal::speed_over_limit: return "speed_over_limit";
    case Refusal::excitation_outside_limits: return "excitation_outside_limits";
    case Refusal::excitation_invalid: return "excitation_invalid";
    case Refusal::accel_over_limit: return "accel_over_limit";
    case Refusal::speed_over_extend_capability: return "speed_over_extend_capability";
    case Refusal::speed_over_retract_capability: return "speed_over_retract_capability";
    case Refusal::accel_over_extend_capability: return "accel_over_extend_capability";
    case Refusal::accel_over_retract_capability: return "accel_over_retract_capability";
    case Refusal::no_recorder: return "no_recorder";
  }
  return "invalid";
}

std::string metrics_text(const MetricsSnapshot& snapshot) {
  PrometheusText out;
  daemon_families(out, snapshot);
  axis_families(out, snapshot.axes);
  driver_families(out, snapshot.drivers);
  return out.text();
}

}  // namespace hsa::daemon
