// The seam between an axis and the law that drives its valve.
//
// An axis (daemon/axis/axis_loop.hpp) runs one ControlLaw each base tick. It reads the signals,
// lets its supervisor decide whether and how to drive, and hands the law what it needs; the law
// answers with the valve command. Everything a law is (its parameters, their bounds, its bumpless
// start, the gains an operator may change while it runs, its open-loop path) lives behind this
// interface, so the axis knows no law by name. Laws are chosen by name in the configuration
// (`drive` of an axis) through control/law_registry.cpp; docs/architecture.md shows how to add one.
//
// Two modes reach a law, as the supervisor decides:
// - position: tick() follows the rod setpoint (the cylinder loop, with whatever valve loop the law
//   has beneath it);
// - open loop: open_loop_tick() takes the operator's valve opening u ∈ [-1, 1] straight to the
//   law's valve stage, by the same parts position mode uses beneath its cylinder loop.
//
// Real-time contract: activate(), tick(), open_loop_tick() and set_gains() run on the RT thread
// and allocate, lock and block nothing. check_gains() runs on a normal thread first and throws
// std::invalid_argument with the reason, so set_gains() only ever sees gains it accepts. clone()
// and describe() are for configuration time.
//
// Time: `base_tick` is the index of the base tick the call belongs to (the executive's schedule),
// so after skipped periods a law integrates over the time that passed rather than over calls.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace hsa::control {

struct LawInputs {
  double rod_setpoint_m = 0.0;
  double rod_position_m = 0.0;
  double spool_position_m = 0.0;     // read only by laws that close a spool loop (needs_spool)
  double rod_velocity_ff_m_s = 0.0;  // the setpoint's velocity, for a feed-forward (0: none)
  double rod_accel_ff_m_s2 = 0.0;    // its acceleration (a move's profile; 0: none)
  double rod_jerk_ff_m_s3 = 0.0;     // its jerk (a move's profile; 0: none)
  bool rod_setpoint_planned = false; // a move's profile is under way (PiController: integrator held)
};

struct LawOutput {
  double command = 0.0;            // what the valve command output gets (an opening, a current)
  double opening = 0.0;            // valve opening u in [-1, 1]
  double spool_reference_m = 0.0;  // the spool position asked for (laws with a spool loop)
  bool cylinder_ticked = false;    // the cylinder loop ran on this tick
};

// The gains an operator may change while the law runs (command_t.GAINS), in SI.
struct RuntimeGains {
  double kp = 0.0;  // m⁻¹
  double ki = 0.0;  // m⁻¹s⁻¹

  bool operator==(const RuntimeGains&) const = default;
};

// The largest gains an operator may set at run time. A configuration that gives none gets
// kDefaultGainBoundFactor times the configured gains, so no axis runs unbounded.
struct GainBounds {
  double max_kp = 0.0;  // a runtime kp must be in (0, max_kp]
  double max_ki = 0.0;  // a runtime ki must be in [0, max_ki]
};

inline constexpr double kDefaultGainBoundFactor = 2.0;

class ControlLaw {
 public:
  virtual ~ControlLaw() = default;

  // A new law with the same parameters, not yet activated: one per running axis, and one for a
  // check, from the configuration's copy.
  [[nodiscard]] virtual std::unique_ptr<ControlLaw> clone() const = 0;

  [[nodiscard]] virtual std::string_view name() const noexcept = 0;
  [[nodiscard]] virtual bool needs_spool() const noexcept = 0;
  // The command at which the valve is closed (an opening of 0, a proportional valve's null
  // current): the default safe command.
  [[nodiscard]] virtual double null_command() const noexcept = 0;
  // The valve command's unit as messages write it after a number: "" (an opening) or " A".
  [[nodiscard]] virtual std::string_view command_unit() const noexcept = 0;
  // "" when `command` closes the valve, within `band` (a fraction of the command's full scale)
  // of closed; otherwise what a closing command must be, for the configuration's message.
  [[nodiscard]] virtual std::string safe_command_refusal(double command, double band) const = 0;
  // The rod speed the law's setpoint limiter allows, m/s (finite); the axis's speed bound.
  [[nodiscard]] virtual double max_speed_m_s() const noexcept = 0;
  // Human-readable parameters, one indented line each, for `hsad --check-config`.
  [[nodiscard]] virtual std::string describe() const = 0;

  // Bumpless start from the measured rod and spool and the opening the valve saw last: the first
  // output continues it.
  virtual void activate(double rod_position_m, double spool_position_m, double current_opening) noexcept = 0;
  virtual LawOutput tick(const LawInputs& in, std::uint64_t base_tick) noexcept = 0;
  virtual LawOutput open_loop_tick(double opening, double spool_position_m, std::uint64_t base_tick) noexcept = 0;

  // The setpoint the cylinder loop follows now (after its rate limit), for the following error.
  [[nodiscard]] virtual double limited_setpoint_m() const noexcept = 0;
  // The cylinder loop's integral term (the opening it carries), for the flight recorder; 0 for a
  // law without one.
  [[nodiscard]] virtual double integral() const noexcept { return 0.0; }
  // The command the law wrote on its last sample sits at its limit: what the axis's
  // current_saturated fault judges (a proportional valve's solenoid current clamped to [0, I_max],
  // a servo-valve's opening clamped to the PI's output limit).
  [[nodiscard]] virtual bool saturated() const noexcept = 0;

  [[nodiscard]] virtual RuntimeGains gains() const noexcept = 0;
  [[nodiscard]] virtual GainBounds gain_bounds() const noexcept = 0;
  // Throws std::invalid_argument, naming the gain and its bound, for gains set_gains must not take.
  virtual void check_gains(const RuntimeGains& gains) const = 0;
  // Takes checked gains bumplessly: the output continues, every other state is kept.
  virtual void set_gains(const RuntimeGains& gains) noexcept = 0;
};

}  // namespace hsa::control
