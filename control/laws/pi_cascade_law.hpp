// What the two position laws of the papers share: the cylinder PI of Puglisi et al. (2015) on
// control::Cascade's schedule, its runtime gains and their bounds, and the reading of [axes.pi].
// The laws differ beneath the PI: laws/direct_servo/ sends the opening to a servo-valve,
// laws/proportional_cascade/ closes the spool loop of Canuto et al. (2014) on a proportional
// valve. A law written from scratch implements control::ControlLaw directly.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "control/cascade.hpp"
#include "control/control_law.hpp"
#include "control/gain_gate.hpp"
#include "control/law_settings.hpp"

namespace hsa::control {

// Bounds of the [axes.pi] numbers: what a lab-scale servo-actuator can use. kp = 1e4 opens the
// valve fully at 0.1 mm of error; more is no longer a position loop.
namespace pi_bounds {
inline constexpr double kMaxKp = 1e4;                     // 1/m
inline constexpr double kMaxKi = 1e6;                     // 1/(m s)
inline constexpr double kMaxSpeedMPerS = 5.0;             // rod speed bound, m/s
inline constexpr double kMaxDeadBandM = 0.01;             // PI dead bands, m
inline constexpr double kMaxVelocityFeedforward = 100.0;  // opening per m/s
inline constexpr double kMaxMinGainMarginDb = 40.0;       // min_gain_margin_db
inline constexpr double kMaxMinPhaseMarginDeg = 90.0;     // min_phase_margin_deg, excluded
// Opening per m/s² and per m/s³: 20 times the paper's nominal plant's (motion_feedforward.hpp).
inline constexpr double kMaxAccelFeedforward = 1.0;
inline constexpr double kMaxJerkFeedforward = 0.01;
}  // namespace pi_bounds

// The loop timing a law is configured for: the base tick (the valve loop's period) and how many
// of them make one cylinder-loop period.
struct LawTiming {
  double base_period_s = 1e-4;
  std::uint32_t ticks_per_cylinder_tick = 10;
};

class PiCascadeLaw : public ControlLaw {
 public:
  // Throws std::invalid_argument when the cascade refuses `params`, or when its PI gains are not
  // within finite `bounds` (kp in (0, max_kp], ki in [0, max_ki]). `gate`, when given, judges
  // every runtime gain pair in check_gains() (gain_gate.hpp); the configured gains were judged by
  // read_pi. Laws built from the configuration always have one.
  PiCascadeLaw(const CascadeParams& params, const GainBounds& bounds, std::shared_ptr<const GainGate> gate = nullptr);

  [[nodiscard]] double max_speed_m_s() const noexcept override;
  void activate(double rod_position_m, double spool_position_m, double current_opening) noexcept override;
  LawOutput tick(const LawInputs& in, std::uint64_t base_tick) noexcept override;
  // The opening takes the PI's place above the same valve stage (Cascade::open_loop_tick).
  LawOutput open_loop_tick(double opening, double spool_position_m, std::uint64_t base_tick) noexcept override;
  [[nodiscard]] double limited_setpoint_m() const noexcept override;
  [[nodiscard]] double integral() const noexcept override { return cascade_.cylinder().integral(); }
  // The PI's opening at its output limit: the command of a servo-valve (direct drive). A law with
  // a stage beneath the PI judges that stage's command instead.
  [[nodiscard]] bool saturated() const noexcept override;
  [[nodiscard]] RuntimeGains gains() const noexcept override;
  [[nodiscard]] GainBounds gain_bounds() const noexcept override { return bounds_; }
  // The bounds, then the gate: a refusal names the worst plant and its margin.
  void check_gains(const RuntimeGains& gains) const override;
  void set_gains(const RuntimeGains& gains) noexcept override;

  [[nodiscard]] const Cascade& cascade() const { return cascade_; }

  // [axes.pi] of an axis: the PI's parameters with the period of `timing`, the runtime gain
  // bounds (kDefaultGainBoundFactor times the gains when not given), and the gain gate on Table A3
  // with the minimum margins min_gain_margin_db and min_phase_margin_deg, which the configured
  // gains must pass (the reader's error on kp otherwise, naming the worst plant).
  static PiParams read_pi(const LawSettings& axis, const LawTiming& timing, GainBounds& bounds,
                          std::shared_ptr<const GainGate>& gate);

 protected:
  // One line of describe() for the PI, shared by both laws.
  [[nodiscard]] std::string describe_pi() const;
  [[nodiscard]] const std::shared_ptr<const GainGate>& gate() const { return gate_; }
  Cascade cascade_;

 private:
  GainBounds bounds_;
  std::shared_ptr<const GainGate> gate_;  // immutable, shared by the clones; null: bounds only
};

}  // namespace hsa::control
