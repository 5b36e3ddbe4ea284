#include "tools/hsactl/status_json.hpp"

#include "tools/hsactl/driver_report.hpp"
#include "tools/hsactl/lcm_session.hpp"
#include "tools/hsactl/value_age.hpp"

namespace hsa::ctl {

nlohmann::ordered_json status_json(const std::string& axis, const hsa::status_t& s, const hsa::telemetry_t* t,
                                   const StatusTrust& trust) {
  nlohmann::ordered_json o;
  o["axis"] = axis;
  // false: hsactl had no key, and nothing below is authenticated.
  o["verified"] = trust.verified;
  o["unverified_status"] = trust.unverified_status;
  o["state"] = state_name(s.state);
  o["mode"] = mode_name(s.mode);
  o["holding"] = static_cast<bool>(s.holding);
  o["exciting"] = static_cast<bool>(s.exciting);
  nlohmann::ordered_json faults = nlohmann::ordered_json::array();
  for (int i = 0; i < s.num_faults; ++i) faults.push_back({{"code", s.fault_code[i]}, {"reason", s.fault_reason[i]}});
  o["faults"] = std::move(faults);
  o["setpoints_accepted"] = s.setpoints_accepted;
  o["commands_accepted"] = s.commands_accepted;
  o["rejected_non_finite"] = s.rejected_non_finite;
  o["rejected_out_of_range"] = s.rejected_out_of_range;
  o["rejected_decode"] = s.rejected_decode;
  o["rejected_unknown"] = s.rejected_unknown;
  o["rt_overruns"] = s.rt_overruns;
  o["rt_allocations"] = s.rt_allocations;
  o["rt_locks"] = s.rt_locks;
  o["rt_minor_faults"] = s.rt_minor_faults;
  o["rt_major_faults"] = s.rt_major_faults;
  o["sched_fifo"] = static_cast<bool>(s.sched_fifo);
  o["memory_locked"] = static_cast<bool>(s.memory_locked);
  o["kp"] = s.kp;
  o["ki"] = s.ki;
  o["gain_changes_applied"] = s.gain_changes_applied;
  o["gain_changes_refused"] = s.gain_changes_refused;
  o["gains_refusal"] = s.gains_refusal;
  o["auth_required"] = static_cast<bool>(s.auth_required);
  o["rejected_unknown_operator"] = s.rejected_unknown_operator;
  o["rejected_bad_mac"] = s.rejected_bad_mac;
  o["rejected_replay"] = s.rejected_replay;
  o["rejected_stamp"] = s.rejected_stamp;
  o["rejected_wrong_daemon"] = s.rejected_wrong_daemon;
  o["system"] = s.system;
  o["instance"] = s.instance;
  o["warning"] = s.warning;
  o["lease_holder"] = s.lease_holder;
  o["lease_remaining_s"] = s.lease_remaining_s;
  o["rejected_lease"] = s.rejected_lease;
  o["lease_takeovers"] = s.lease_takeovers;
  o["lease_taken_by"] = s.lease_taken_by;
  o["lease_taken_from"] = s.lease_taken_from;
  o["lease_taken_at_us"] = s.lease_taken_at_us;
  // The flight recorder (status_t.captures_*): counts and the condition armed ("" none).
  o["recorder"] = {{"captures_written", s.captures_written},
                   {"triggers_merged", s.capture_triggers_merged},
                   {"triggers_dropped", s.capture_triggers_dropped},
                   {"write_failures", s.capture_write_failures},
                   {"condition", s.capture_condition}};
  nlohmann::ordered_json drivers = nlohmann::ordered_json::array();
  for (const hsa::driver_status_t& d : s.drivers) drivers.push_back(driver_json(d));
  o["drivers"] = std::move(drivers);
  // The answers to the most recent commands, oldest first.
  nlohmann::ordered_json results = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < s.result_operator.size(); ++i) {
    results.push_back({{"operator", s.result_operator[i]},
                       {"counter", s.result_counter.at(i)},
                       {"accepted", static_cast<bool>(s.result_accepted.at(i))},
                       {"reason", s.result_reason.at(i)}});
  }
  o["results"] = std::move(results);
  // The rod as hsad's (authenticated) status has it; the telemetry fields below are not authenticated.
  o["status_sample_utime"] = s.sample_utime;
  o["status_position_m"] = s.position_m;
  o["status_setpoint_m"] = s.setpoint_m;
  // How old status_position_m is at the status's time, and whether hsad still reads it.
  const ValueAge position_age = status_position_age(s);
  o["status_position_age_s"] = static_cast<double>(position_age.age_us) * 1e-6;
  o["status_position_stale"] = position_age.stale;
  if (t != nullptr) {
    o["position_m"] = t->position_m;
    o["setpoint_m"] = t->setpoint_m;
    o["pressure_a_pa"] = t->pressure_a_pa;
    o["pressure_b_pa"] = t->pressure_b_pa;
    // The valve as the last telemetry sample saw it: the loop's opening, what went to the valve
    // output (opening or current reference) and the spool feedback, if the axis has one.
    o["telemetry_state"] = state_name(t->state);
    o["velocity_m_s"] = t->velocity_m_s;
    o["valve_opening"] = t->valve_opening;
    o["current_ref_a"] = t->current_ref_a;
    o["valve_enabled"] = static_cast<bool>(t->valve_enabled);
    o["spool_position_m"] = t->spool_position_m;
    // Each bound input's age at the sample and whether it is live; the e-stop's reading.
    nlohmann::ordered_json inputs = nlohmann::ordered_json::object();
    for (const InputAgeView& in : telemetry_inputs(*t)) {
      if (in.age.age_us < 0) continue;
      inputs[in.key] = {{"age_s", static_cast<double>(in.age.age_us) * 1e-6}, {"stale", in.age.stale}};
    }
    o["inputs"] = std::move(inputs);
    if (t->estop_age_us >= 0) o["estop"] = static_cast<bool>(t->estop);
  }
  return o;
}

}  // namespace hsa::ctl
