#include "daemon/lcm_bridge/message_conversion.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>

#include "hsa/command_t.hpp"

namespace hsa::daemon {

static_assert(static_cast<std::int8_t>(DriverEntry::Link::none) == hsa::driver_status_t::LINK_NONE);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::up) == hsa::driver_status_t::LINK_UP);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::down) == hsa::driver_status_t::LINK_DOWN);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::not_answering) == hsa::driver_status_t::LINK_NOT_ANSWERING);

namespace {

std::int64_t as_int64(std::uint64_t n) {
  return static_cast<std::int64_t>(std::min<std::uint64_t>(n, std::numeric_limits<std::int64_t>::max()));
}

std::int8_t wire_state(AxisState s) {
  switch (s) {
    case AxisState::init: return hsa::status_t::STATE_INIT;
    case AxisState::disabled: return hsa::status_t::STATE_DISABLED;
    case AxisState::enabled: return hsa::status_t::STATE_ENABLED;
    case AxisState::fault: return hsa::status_t::STATE_FAULT;
    case AxisState::estop: return hsa::status_t::STATE_ESTOP;
  }
  return hsa::status_t::STATE_FAULT;
}

std::int8_t wire_mode(ControlMode m) {
  return m == ControlMode::open_loop ? hsa::command_t::MODE_VALVE_OPENING : hsa::command_t::MODE_POSITION;
}

// The status code of a fault class: its table line (fault.hpp).
std::int8_t wire_fault(FaultReason r) {
  switch (r) {
    case FaultReason::none: break;
#define HSA_FAULT_WIRE(reason, wire, kind, summary, detail, scale) \
  case FaultReason::reason: return hsa::status_t::wire;
    HSA_FAULT_REASONS(HSA_FAULT_WIRE)
#undef HSA_FAULT_WIRE
  }
  return 0;
}

// The stale bit of an input on the wire (telemetry_t.STALE_*): bit signal − 1, FaultSignal's order.
static_assert(hsa::telemetry_t::STALE_POSITION == 1 << (static_cast<int>(FaultSignal::position) - 1));
static_assert(hsa::telemetry_t::STALE_PRESSURE_A == 1 << (static_cast<int>(FaultSignal::pressure_a) - 1));
static_assert(hsa::telemetry_t::STALE_PRESSURE_B == 1 << (static_cast<int>(FaultSignal::pressure_b) - 1));
static_assert(hsa::telemetry_t::STALE_SPOOL == 1 << (static_cast<int>(FaultSignal::spool) - 1));
static_assert(hsa::telemetry_t::STALE_ESTOP == 1 << (static_cast<int>(FaultSignal::estop) - 1));

const InputAge& input(const TelemetrySample& s, FaultSignal which) {
  return s.inputs[static_cast<std::size_t>(which) - 1];
}

// µs on the wire; −1 (no such input) stays −1.
std::int64_t age_us(const InputAge& a) { return a.age_ns < 0 ? -1 : a.age_ns / 1000; }

std::size_t results_of(const StatusSample& s) { return std::min<std::size_t>(s.num_results, StatusSample::kMaxResults); }

// A fixed, NUL-terminated array as a string (the whole array when no NUL ends it).
template <std::size_t N>
std::string text(const char (&chars)[N]) {
  return std::string(chars, ::strnlen(chars, N));
}

hsa::driver_status_t to_message(const DriverEntry& d) {
  hsa::driver_status_t m{};
  m.name = text(d.name);
  m.plugin = text(d.plugin);
  m.state = text(d.state);
  m.failure = text(d.failure);
  m.link = static_cast<std::int8_t>(d.link);
  m.last_error = text(d.last_error);
  const std::size_t n = std::min<std::size_t>(d.num_counters, DriverEntry::kMaxCounters);
  m.num_counters = static_cast<std::int16_t>(n);
  for (std::size_t i = 0; i < n; ++i) {
    m.counter_name.push_back(text(d.counter_name[i]));
    m.counter_value.push_back(d.counter_value[i]);
  }
  return m;
}

}  // namespace

hsa::telemetry_t to_lcm(const TelemetrySample& s) {
  hsa::telemetry_t t{};
  t.utime = s.utime;
  t.seq = as_int64(s.tick);
  t.position_m = s.position_m;
  t.velocity_m_s = s.velocity_m_s;
  t.pressure_a_pa = s.pressure_a_pa;
  t.pressure_b_pa = s.pressure_b_pa;
  t.load_pressure_pa = s.load_pressure_pa;
  t.spool_position_m = s.spool_position_m;
  t.setpoint_m = s.setpoint_m;
  t.following_error_m = s.following_error_m;
  t.valve_opening = s.valve_opening;
  t.current_ref_a = s.current_ref_a;
  t.valve_enabled = s.valve_enabled;
  t.setpoint_utime = s.setpoint_utime;
  t.state = wire_state(s.state);
  t.holding = s.holding;
  t.exciting = s.exciting;
  t.lateness_ns = s.lateness_ns;
  t.lateness_max_ns = s.lateness_max_ns;
  t.exec_time_ns = s.exec_time_ns;
  t.exec_time_max_ns = s.exec_time_max_ns;
  t.overruns = s.overruns;
  t.position_age_us = age_us(input(s, FaultSignal::position));
  t.pressure_a_age_us = age_us(input(s, FaultSignal::pressure_a));
  t.pressure_b_age_us = age_us(input(s, FaultSignal::pressure_b));
  t.spool_age_us = age_us(input(s, FaultSignal::spool));
  t.estop_age_us = age_us(input(s, FaultSignal::estop));
  t.estop = s.estop;
  int stale = 0;
  for (std::size_t i = 0; i < kFaultSignalCount; ++i) stale |= s.inputs[i].stale ? 1 << i : 0;
  t.stale = static_cast<std::int8_t>(stale);
  return t;
}

hsa::status_t to_lcm(const StatusSample& s, const AxisCounters& c, std::int64_t utime_us) {
  hsa::status_t m{};
  m.utime = utime_us;
  m.state = wire_state(s.state);
  m.mode = wire_mode(s.mode);
  m.holding = s.holding;
  m.exciting = s.exciting;

  if (s.fault != FaultReason::none) {
    m.num_faults = 1;
    m.fault_code.push_back(wire_fault(s.fault));
    m.fault_reason.push_back(text(s.fault_text));
  }

  m.setpoints_accepted = as_int64(c.setpoints_accepted);
  m.commands_accepted = as_int64(c.commands_accepted);
  m.rejected_decode = as_int64(c.rejected_for(RejectReason::decode));
  m.rejected_non_finite = as_int64(c.rejected_for(RejectReason::non_finite));
  m.rejected_out_of_range = as_int64(c.rejected_for(RejectReason::out_of_range));
  m.rejected_unknown = as_int64(c.rejected_for(RejectReason::unknown));
  m.lcm_seq_gaps = as_int64(c.lcm_seq_gaps);
  m.rejected_unknown_operator = as_int64(c.rejected_for(RejectReason::unknown_operator));
  m.rejected_bad_mac = as_int64(c.rejected_for(RejectReason::bad_mac));
  m.rejected_replay = as_int64(c.rejected_for(RejectReason::replay));
  m.rejected_stamp = as_int64(c.rejected_for(RejectReason::stale_stamp));
  m.rejected_lease = as_int64(c.rejected_for(RejectReason::lease_held));
  m.rejected_wrong_daemon = as_int64(c.rejected_for(RejectReason::wrong_daemon));
  m.setpoint_ring_drops = as_int64(c.setpoint_ring_drops);
  m.command_ring_drops = as_int64(c.command_ring_drops);
  m.telemetry_ring_drops = as_int64(c.telemetry_ring_drops);
  m.status_ring_drops = as_int64(c.status_ring_drops);

  m.rt_overruns = s.rt_overruns;
  m.rt_allocations = s.rt_allocations;
  m.rt_locks = s.rt_locks;
  m.rt_minor_faults = s.rt_minor_faults;
  m.rt_major_faults = s.rt_major_faults;

  m.sched_fifo = s.sched_fifo;
  m.memory_locked = s.memory_locked;
  m.rt_priority = s.rt_priority;
  m.rt_cpu = s.rt_cpu;

  m.kp = s.kp;
  m.ki = s.ki;
  m.gain_changes_applied = s.gain_changes_applied;
  m.gain_changes_refused = s.gain_changes_refused;
  m.gains_refusal = text(s.gains_refusal);
  m.captures_written = s.captures_written;
  m.capture_triggers_merged = s.capture_triggers_merged;
  m.capture_triggers_dropped = s.capture_triggers_dropped;
  m.capture_write_failures = s.capture_write_failures;
  m.capture_condition = text(s.capture_condition);
  m.num_drivers = static_cast<std::int16_t>(std::min<std::size_t>(s.num_drivers, StatusSample::kMaxDrivers));
  m.drivers.resize(static_cast<std::size_t>(m.num_drivers));
  for (std::size_t i = 0; i < m.drivers.size(); ++i) m.drivers[i] = to_message(s.drivers[i]);
  const std::size_t results = results_of(s);
  m.num_results = static_cast<std::int16_t>(results);
  for (std::size_t i = 0; i < results; ++i) {
    const CommandResultEntry& r = s.results[i];
    m.result_operator.push_back(text(r.from.operator_id));
    m.result_counter.push_back(r.from.counter);
    m.result_accepted.push_back(r.accepted);
    m.result_reason.push_back(text(r.reason));
  }
  return m;
}

bool status_changed(const StatusSample& previous, const StatusSample& next) {
  if (previous.state != next.state || previous.mode != next.mode || previous.holding != next.holding ||
      previous.exciting != next.exciting) {
    return true;  // an operator waiting for an excitation's end hears at once
  }
  // An operator waiting for a GAINS command to be applied or refused hears at once.
  if (previous.gain_changes_applied != next.gain_changes_applied ||
      previous.gain_changes_refused != next.gain_changes_refused) {
    return true;
  }
  if (previous.fault != next.fault) return true;
  // A sender waiting for the answer to its command hears at once.
  const std::size_t n = results_of(next);
  if (results_of(previous) != n) return true;
  return n != 0 && (previous.results[n - 1].from.counter != next.results[n - 1].from.counter ||
                    std::strncmp(previous.results[n - 1].from.operator_id, next.results[n - 1].from.operator_id,
                                 kOperatorIdSize) != 0);
}

}  // namespace hsa::daemon
