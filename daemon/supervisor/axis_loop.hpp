// The per-axis work of one RT cycle: read the axis's signals, judge them (AxisSupervisor), run
// the loops (control::Cascade) and write the valve outputs, then describe the cycle in
// AxisTelemetry.
//
// cycle() runs on the RT thread after the executive's driver read() and before its write(). It
// allocates nothing, takes no lock and does not block: every object it touches is built in the
// constructor. When the supervisor's decision is not to drive (any state but ENABLED, including a
// fault found in this very cycle) the valve command is set to AxisParams::safe_command and the
// valve enable off before cycle() returns, and the loops are left as they are (frozen); the next
// enable re-activates them bumplessly from the measured position and spool.
//
// The PI's gains Kp and Ki change at run time through request_params() from one normal thread:
// the request is validated there (that may throw; nothing else of the loops may change, and the
// gains must lie within the axis's GainBounds), handed over through a wait-free TripleBuffer, and
// taken at the start of the next cycle by control::Cascade::set_cylinder_gains, which keeps the
// opening, the PI's setpoint limiter, the state predictor and the valve law as they are. The
// change is therefore bumpless on both drives, the proportional valve's current included. Mode
// changes are operator commands (see AxisCommand) and reach cycle() with the operator inputs, so
// they too apply at a cycle boundary.
//
// Time: `tick` is the index of the base tick this cycle was scheduled for (CycleTiming::tick).
// The cascade and the open-loop valve path take it, so after periods the executive skipped they
// integrate over the time that passed (see control::Cascade). The time since the previous cycle
// goes to the supervisor, which faults an ENABLED axis on too long a gap (blind_time). A command
// that comes out non-finite faults the axis in the same cycle (control_output), with the safe
// command written and the valve enable off: no NaN reaches an output.
//
// Open-loop mode with a proportional valve still closes the valve loop on the spool: the loop
// keeps its own state predictor and valve law for that path, with the cascade's parameters.
#pragma once

#include <cstdint>

#include "control/cascade.hpp"
#include "control/state_predictor.hpp"
#include "control/valve_law.hpp"
#include "daemon/supervisor/axis_params.hpp"
#include "daemon/supervisor/axis_signals.hpp"
#include "daemon/supervisor/axis_supervisor.hpp"
#include "daemon/supervisor/axis_telemetry.hpp"
#include "daemon/supervisor/operator_input.hpp"
#include "drivers/triple_buffer.hpp"

namespace hsa::daemon {

class AxisLoop {
 public:
  // Throws std::invalid_argument when the parameters are inconsistent (a cascade the control
  // code refuses; a proportional drive without a spool signal).
  AxisLoop(const AxisParams& params, AxisSignals signals);

  AxisLoop(const AxisLoop&) = delete;
  AxisLoop& operator=(const AxisLoop&) = delete;

  // RT thread, once per base tick. `tick` is this cycle's base-tick index; kNextTick (tests that
  // step one tick at a time) means the tick after the last one.
  static constexpr std::uint64_t kNextTick = UINT64_MAX;
  void cycle(std::int64_t t_ns, const AxisInputsFromOperator& op,
             const ExecutiveInputs& executive = {}, std::uint64_t tick = kNextTick) noexcept;

  // Normal thread (a single one). Throws std::invalid_argument, with the reason and nothing
  // published, when `params` differ from the loops in use in anything but cylinder.kp and
  // cylinder.ki, or when those are not finite, kp is not in (0, max_kp] or ki not in [0, max_ki].
  void request_params(const control::CascadeParams& params);

  // The state after the last cycle(): read on the RT thread (or between cycles in a test), which
  // then copies the telemetry into its ring.
  [[nodiscard]] const AxisTelemetry& telemetry() const { return telemetry_; }
  [[nodiscard]] const AxisSupervisor& supervisor() const { return supervisor_; }
  [[nodiscard]] const control::Cascade& cascade() const { return cascade_; }
  // As constructed; the loop parameters in use are cascade().params().
  [[nodiscard]] const AxisParams& params() const { return params_; }
  [[nodiscard]] const GainBounds& gain_bounds() const { return gain_bounds_; }
  [[nodiscard]] const AxisSignals& signals() const { return signals_; }

 private:
  void activate(double position_m, double spool_m, double opening) noexcept;
  void apply_pending_params() noexcept;
  void drive_safe() noexcept;

  const AxisParams params_;
  const GainBounds gain_bounds_;
  AxisSignals signals_;
  AxisSupervisor supervisor_;
  control::Cascade cascade_;
  control::StatePredictor open_predictor_;  // open-loop path of a proportional drive
  control::ValveLaw open_law_;
  io::TripleBuffer<control::CascadeParams> pending_;

  std::uint64_t param_changes_ = 0;
  bool driving_ = false;        // the last cycle drove the valve
  double applied_opening_ = 0.0;  // the opening the valve saw last cycle (for bumpless starts)
  bool last_saturated_ = false;
  bool have_cycle_ = false;        // a cycle ran before: last_cycle_ns_ and last_tick_ hold
  std::int64_t last_cycle_ns_ = 0;
  std::uint64_t last_tick_ = 0;
  double last_position_m_ = 0.0;
  std::int64_t last_position_stamp_ns_ = 0;
  bool have_velocity_sample_ = false;
  double velocity_m_s_ = 0.0;
  AxisTelemetry telemetry_{};
};

}  // namespace hsa::daemon
