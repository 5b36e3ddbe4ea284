// The per-axis work of one RT cycle: read the axis's signals, judge them (AxisSupervisor), run
// the axis's control law (control::ControlLaw) and write the valve outputs, then describe the
// cycle in AxisTelemetry.
//
// cycle() runs on the RT thread after the executive's driver read() and before its write(). It
// allocates nothing, takes no lock and does not block: every object it touches is built in the
// constructor. When the supervisor's decision is not to drive (any state but ENABLED, including a
// fault found in this very cycle) the valve command is set to AxisParams::safe_command and the
// valve enable off before cycle() returns, and the loops are left as they are (frozen); the next
// enable re-activates them bumplessly from the measured position and spool.
//
// The law's runtime gains change through request_gains() from one normal thread: the law checks
// them there (that may throw, with the reason), they are handed over through a wait-free
// TripleBuffer, and the law takes them at the start of the next cycle (ControlLaw::set_gains),
// keeping every other state, so the change is bumpless. Mode changes are operator commands (see
// AxisCommand) and reach cycle() with the operator inputs, so they too apply at a cycle boundary.
//
// Time: `tick` is the index of the base tick this cycle was scheduled for (CycleTiming::tick).
// The law takes it, so after periods the executive skipped it integrates over the time that
// passed. The time since the previous cycle
// goes to the supervisor, which faults an ENABLED axis on too long a gap (blind_time). A command
// that comes out non-finite faults the axis in the same cycle (control_output), with the safe
// command written and the valve enable off: no NaN reaches an output.
//
// An excitation (AxisSupervisor, Decision::exciting) runs the law as the identification's P
// controller: in its first cycle the loop re-activates the law from the measured rod with opening
// 0 (integrator reset: the opening is kp·e from there, the integral off, as
// tests/analyze/identification_run.hpp models the run) and sets the gains {excite kp, 0}; when it
// ends, the gains in use before come back through set_gains, which is bumpless (the integral takes
// up the last output). Gains an operator sets meanwhile end the excitation and are the ones that
// come back. Both happen on the RT thread with the law's own noexcept calls.
//
// Open-loop mode hands the operator's opening to the law's own valve stage
// (ControlLaw::open_loop_tick): with a proportional valve, the spool loop still closes.
#pragma once

#include <cstdint>

#include <memory>

#include "control/control_law.hpp"
#include "daemon/axis/axis_params.hpp"
#include "daemon/axis/axis_signals.hpp"
#include "daemon/supervisor/axis_supervisor.hpp"
#include "daemon/axis/axis_telemetry.hpp"
#include "daemon/supervisor/operator_input.hpp"
#include "lockfree/triple_buffer.hpp"

namespace hsa::daemon {

class AxisLoop {
 public:
  // Throws std::invalid_argument when the parameters are inconsistent (no law; a law that needs a
  // spool signal without one).
  AxisLoop(const AxisParams& params, AxisSignals signals);

  AxisLoop(const AxisLoop&) = delete;
  AxisLoop& operator=(const AxisLoop&) = delete;

  // RT thread, once per base tick. `tick` is this cycle's base-tick index; kNextTick (tests that
  // step one tick at a time) means the tick after the last one.
  static constexpr std::uint64_t kNextTick = UINT64_MAX;
  void cycle(std::int64_t t_ns, const AxisInputsFromOperator& op,
             const ExecutiveInputs& executive = {}, std::uint64_t tick = kNextTick) noexcept;

  // Normal thread (a single one). Throws std::invalid_argument, with the axis and the law's
  // reason and nothing published, for gains the law refuses (ControlLaw::check_gains).
  void request_gains(const control::RuntimeGains& gains);

  // The state after the last cycle(): read on the RT thread (or between cycles in a test), which
  // then copies the telemetry into its ring.
  [[nodiscard]] const AxisTelemetry& telemetry() const { return telemetry_; }
  [[nodiscard]] const AxisSupervisor& supervisor() const { return supervisor_; }
  // The law in use (its gains as last applied).
  [[nodiscard]] const control::ControlLaw& law() const { return *law_; }
  // As constructed.
  [[nodiscard]] const AxisParams& params() const { return params_; }
  [[nodiscard]] const AxisSignals& signals() const { return signals_; }

 private:
  void activate(double position_m, double spool_m, double opening) noexcept;
  void apply_pending_gains() noexcept;
  // Switches the law to and from an excitation's P gain as the decision says (see above).
  void follow_excitation(const Decision& d, double position_m, double spool_m) noexcept;
  void drive_safe() noexcept;

  const AxisParams params_;
  AxisSignals signals_;
  AxisSupervisor supervisor_;
  std::unique_ptr<control::ControlLaw> law_;
  lockfree::TripleBuffer<control::RuntimeGains> pending_;

  std::uint64_t param_changes_ = 0;
  bool driving_ = false;        // the last cycle drove the valve
  double applied_opening_ = 0.0;  // the opening the valve saw last cycle (for bumpless starts)
  bool last_saturated_ = false;
  bool exciting_ = false;                   // the law runs an excitation's P gain
  std::uint64_t excitation_ = 0;            // which run (Decision::excitation)
  control::RuntimeGains gains_after_excitation_{};  // the gains that come back when it ends
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
