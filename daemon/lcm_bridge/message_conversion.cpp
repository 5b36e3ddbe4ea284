#include "daemon/lcm_bridge/message_conversion.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>

namespace hsa::daemon {

static_assert(static_cast<std::int8_t>(MsgAxisState::init) == hsa::status_t::STATE_INIT);
static_assert(static_cast<std::int8_t>(MsgAxisState::disabled) == hsa::status_t::STATE_DISABLED);
static_assert(static_cast<std::int8_t>(MsgAxisState::enabled) == hsa::status_t::STATE_ENABLED);
static_assert(static_cast<std::int8_t>(MsgAxisState::fault) == hsa::status_t::STATE_FAULT);
static_assert(static_cast<std::int8_t>(MsgAxisState::estop) == hsa::status_t::STATE_ESTOP);
static_assert(static_cast<std::int8_t>(MsgFaultCode::sensor) == hsa::status_t::FAULT_SENSOR);
static_assert(static_cast<std::int8_t>(MsgFaultCode::encoder) == hsa::status_t::FAULT_ENCODER);
static_assert(static_cast<std::int8_t>(MsgFaultCode::pressure) == hsa::status_t::FAULT_PRESSURE);
static_assert(static_cast<std::int8_t>(MsgFaultCode::soft_limit) == hsa::status_t::FAULT_SOFT_LIMIT);
static_assert(static_cast<std::int8_t>(MsgFaultCode::following_error) == hsa::status_t::FAULT_FOLLOWING_ERROR);
static_assert(static_cast<std::int8_t>(MsgFaultCode::current_saturation) == hsa::status_t::FAULT_CURRENT_SATURATION);
static_assert(static_cast<std::int8_t>(MsgFaultCode::overruns) == hsa::status_t::FAULT_OVERRUNS);
static_assert(static_cast<std::int8_t>(MsgFaultCode::driver) == hsa::status_t::FAULT_DRIVER);
static_assert(static_cast<std::int8_t>(MsgFaultCode::estop) == hsa::status_t::FAULT_ESTOP);
static_assert(static_cast<std::int8_t>(MsgFaultCode::blind_time) == hsa::status_t::FAULT_BLIND_TIME);
static_assert(static_cast<std::int8_t>(MsgFaultCode::control_output) == hsa::status_t::FAULT_CONTROL_OUTPUT);
static_assert(static_cast<std::int8_t>(MsgFaultCode::inputs_not_ready) == hsa::status_t::FAULT_INPUTS_NOT_READY);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::none) == hsa::driver_status_t::LINK_NONE);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::up) == hsa::driver_status_t::LINK_UP);
static_assert(static_cast<std::int8_t>(DriverEntry::Link::down) == hsa::driver_status_t::LINK_DOWN);

namespace {

std::int64_t as_int64(std::uint64_t n) {
  return static_cast<std::int64_t>(std::min<std::uint64_t>(n, std::numeric_limits<std::int64_t>::max()));
}

std::size_t active_faults(const StatusSample& s) { return std::min<std::size_t>(s.num_faults, StatusSample::kMaxFaults); }

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
  t.state = static_cast<std::int8_t>(s.state);
  t.holding = s.holding;
  t.lateness_ns = s.lateness_ns;
  t.lateness_max_ns = s.lateness_max_ns;
  t.exec_time_ns = s.exec_time_ns;
  t.exec_time_max_ns = s.exec_time_max_ns;
  t.overruns = s.overruns;
  return t;
}

hsa::status_t to_lcm(const StatusSample& s, const AxisCounters& c, std::int64_t utime_us) {
  hsa::status_t m{};
  m.utime = utime_us;
  m.state = static_cast<std::int8_t>(s.state);
  m.mode = static_cast<std::int8_t>(s.mode);
  m.holding = s.holding;

  const std::size_t n = active_faults(s);
  m.num_faults = static_cast<std::int16_t>(n);
  m.fault_code.reserve(n);
  m.fault_reason.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const FaultEntry& f = s.faults[i];
    m.fault_code.push_back(static_cast<std::int8_t>(f.code));
    // The RT side may fill the whole array: never read past it looking for a NUL.
    m.fault_reason.emplace_back(f.reason, ::strnlen(f.reason, FaultEntry::kReasonSize));
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
  m.gains_refusal.assign(s.gains_refusal, ::strnlen(s.gains_refusal, FaultEntry::kReasonSize));
  m.num_drivers = static_cast<std::int16_t>(std::min<std::size_t>(s.num_drivers, StatusSample::kMaxDrivers));
  m.drivers.resize(static_cast<std::size_t>(m.num_drivers));
  for (std::size_t i = 0; i < m.drivers.size(); ++i) m.drivers[i] = to_message(s.drivers[i]);
  m.result_operator.assign(s.result_operator, ::strnlen(s.result_operator, kOperatorIdSize));
  m.result_counter = s.result_counter;
  m.result_accepted = s.result_accepted;
  m.result_reason.assign(s.result_reason, ::strnlen(s.result_reason, FaultEntry::kReasonSize));
  return m;
}

bool status_changed(const StatusSample& previous, const StatusSample& next) {
  if (previous.state != next.state || previous.mode != next.mode || previous.holding != next.holding) return true;
  // An operator waiting for a GAINS command to be applied or refused hears at once.
  if (previous.gain_changes_applied != next.gain_changes_applied ||
      previous.gain_changes_refused != next.gain_changes_refused) {
    return true;
  }
  const std::size_t n = active_faults(next);
  if (active_faults(previous) != n) return true;
  for (std::size_t i = 0; i < n; ++i) {
    if (previous.faults[i].code != next.faults[i].code) return true;
  }
  return false;
}

}  // namespace hsa::daemon
