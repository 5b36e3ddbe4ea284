#pragma once

#include <cstdint>
#include <optional>

#include "control/control_law.hpp"
#include "control/pi_controller.hpp"
#include "control/state_predictor.hpp"
#include "control/valve_law.hpp"
#include "control/valve_model_predictor.hpp"
#include "control/valve_predictive.hpp"

namespace hsa::control {

// The cascade of the two loops (docs/architecture.md, data flow): rod position error → PI (Puglisi et al. 2015) →
// valve opening u ∈ [-1, 1] → spool position reference → state predictor (Canuto et al. 2014, eqs 15–16) +
// valve law (eq 31) → solenoid current reference.
//
// tick() is called at the valve loop's rate (10 kHz); the PI runs on the first of every
// `valve_ticks_per_cylinder_tick` ticks (1 kHz), and its opening is held in between. The opening
// maps linearly onto the spool stroke around hydraulic zero: x_ref = u · spool_at_full_opening_m,
// so +1 is +1.25 mm and -1 is -1.25 mm on the proportional valve being modelled (its stroke
// continues to -2.5 mm at spring rest, outside the range the PI can command).
//
// Time is an input, not a count of calls: tick(in, k) takes the index k of the base tick (the
// valve period) this call belongs to, from the caller's scheduler. After activate() the first
// tick anchors the PI's schedule at k0; the PI then runs whenever (k − k0) / N changes, with
// N = valve_ticks_per_cylinder_tick, once however far k jumped, and integrates over the PI
// periods that elapsed; the valve loop integrates over the k − k_last valve periods elapsed. A
// skipped period (the executive drops periods it overran) therefore leaves no loop behind real
// time. tick(in) is tick(in, k_last + 1): calls on consecutive ticks, bit for bit the schedule of
// a call counter. Ticks that do not advance count as the next tick.
//
// The valve law's predictor is the paper's (eqs 15–16, `predictor`) unless the law's parameters
// enable the one driven by the identified valve (params.valve.model_predictor,
// valve_model_predictor.hpp): that one then runs in its place, and is told after every law update
// the current the law output (its model's input). Over skipped periods it is stepped once per
// missed period with the measurement and the last current held (the drive held that current), at
// most StatePredictor::kMaxCatchUp of them, as the paper's predictor catches up.
//
// With params.valve.predictive enabled (valve_predictive.hpp), the predictive law runs the valve
// loop in place of the predictor and eq 31: it reads the LVDT itself, through its own model and
// Kalman filter, and catches up on skipped periods the same way. Its reference is averaged over
// the valve ticks of one PI period (its reference_window_samples), the PI's opening being held
// over them.
//
// In direct mode, for a servo-valve with its own spool electronics, the valve loop is skipped and
// the command is the opening u itself.
enum class ValveDrive {
  proportional,  // command = solenoid current reference (A), from the valve loop
  direct,        // command = valve opening u in [-1, 1]
};

struct CascadeParams {
  PiParams cylinder{};
  std::uint32_t valve_ticks_per_cylinder_tick = 10;
  ValveDrive drive = ValveDrive::proportional;
  double spool_at_full_opening_m = 1.25e-3;
  PredictorGains predictor = predictor_gains(kTable2Gamma);
  ValveLawParams valve{};

  bool operator==(const CascadeParams&) const = default;
};

class Cascade {
 public:
  // Throws std::invalid_argument when the PI period is not valve period × ticks per cylinder
  // tick (to 1e-9 relative), or when a component rejects its parameters (the model predictor's
  // included, when enabled on a proportional drive).
  explicit Cascade(const CascadeParams& params);

  // Bumpless start: the PI starts from the opening `current_opening` at the rod's position, the
  // predictor (whichever runs) at rest at the spool's position, the valve integrator empty. The
  // next tick runs the PI.
  void activate(double rod_position_m, double spool_position_m, double current_opening = 0.0) noexcept;

  LawOutput tick(const LawInputs& in, std::uint64_t base_tick) noexcept;
  LawOutput tick(const LawInputs& in) noexcept { return tick(in, anchored_ ? last_tick_ + 1 : 0); }

  // Open loop: the opening u goes to the valve stage as the PI's output would (u · spool stroke
  // as the spool reference, then the state predictor and valve law in proportional mode; u itself
  // in direct mode), through the same parts and on the same tick count as tick(). The PI is left
  // as it is; activate() before position mode runs again.
  LawOutput open_loop_tick(double opening, double spool_position_m, std::uint64_t base_tick) noexcept;

  // Swaps the PI's Kp and Ki at run time, bumplessly (PiController::set_gains: the held opening
  // stays what it was, and the next PI sample starts from it). Only the gains change: the PI's
  // setpoint limiter, the state predictor, the valve law's integrator and the tick phase keep
  // their state, so on a proportional valve the current reference does not step either. Returns
  // false, changing nothing, for gains PiController refuses; allocates nothing.
  [[nodiscard]] bool set_cylinder_gains(double kp, double ki) noexcept;

  [[nodiscard]] const PiController& cylinder() const noexcept { return pi_; }
  // The paper's predictor; idle (left at its last reset) while the model predictor runs.
  [[nodiscard]] const StatePredictor& predictor() const { return predictor_; }
  // The model predictor when it runs in the paper's predictor's place, nullptr otherwise.
  [[nodiscard]] const ValveModelPredictor* model_predictor() const noexcept {
    return model_predictor_ ? &*model_predictor_ : nullptr;
  }
  [[nodiscard]] const ValveLaw& valve() const { return law_; }
  // The predictive law when it runs the valve loop, nullptr otherwise.
  [[nodiscard]] const ValvePredictiveLaw* predictive() const noexcept { return predictive_ ? &*predictive_ : nullptr; }
  // The valve loop's current command sits at its limit: eq 31's clamp, or the predictive law's box.
  [[nodiscard]] bool valve_saturated() const noexcept { return predictive_ ? predictive_->saturated() : law_.saturated(); }
  [[nodiscard]] const CascadeParams& params() const noexcept { return params_; }

 private:
  // Valve periods from the last tick to `base_tick` (1 on the first tick after activate()), and
  // the tick bookkeeping moved on.
  // Inlined into every tick: as calls they cost a quarter of the tick (bench_control_tick).
  [[gnu::always_inline]] inline std::uint64_t advance_to(std::uint64_t base_tick) noexcept;
  [[gnu::always_inline]] inline LawOutput valve_stage(double opening, double spool_position_m,
                                                      std::uint64_t elapsed) noexcept;
  // The valve loop's predictor and law on the model predictor, out of line: a tick without it
  // carries one test of model_predicted_ (bench_control_tick).
  [[gnu::noinline]] double model_predicted_law(double reference_m, double spool_position_m,
                                               std::uint64_t elapsed) noexcept;
  [[gnu::always_inline]] inline void run_cylinder(const LawInputs& in, std::uint64_t periods) noexcept;
  // Every tick but the next one after a tick(): the first after activate(), skipped or repeated
  // ticks, the first after open-loop ticks. Out of line, so that the next tick's path (tick())
  // carries none of their bookkeeping.
  [[gnu::noinline]] LawOutput tick_after_gap(const LawInputs& in, std::uint64_t base_tick) noexcept;

  // The tick bookkeeping first, away from the parameters (the PI's feed-forward schedule alone is
  // a kilobyte): every tick reads and writes it.
  bool anchored_ = false;           // a tick since activate(): the PI schedule has its origin
  std::uint64_t ticks_per_cylinder_tick_;  // N = params_.valve_ticks_per_cylinder_tick
  std::uint64_t last_tick_ = 0;
  // (k − k0) / N and (k − k0) mod N of the last tick, kept as the ticks advance: a 64-bit division
  // on every 10 kHz tick cost more than the PI itself.
  std::uint64_t window_ = 0;
  std::uint64_t phase_ = 0;
  std::uint64_t last_window_ = 0;   // window_ of the PI's last run
  bool model_predicted_ = false;    // model_predictor_ runs instead of predictor_
  bool predictive_law_ = false;     // predictive_ runs instead of a predictor and law_

  CascadeParams params_;
  PiController pi_;
  StatePredictor predictor_;
  ValveLaw law_;
  // Constructed (delay line sized) with the cascade when enabled: nothing in tick() allocates.
  std::optional<ValveModelPredictor> model_predictor_;
  std::optional<ValvePredictiveLaw> predictive_;  // the same: its matrices sized with the cascade
};

}  // namespace hsa::control
