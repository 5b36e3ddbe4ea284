// The setpoint of a closed-loop identification run (Puglisi et al. 2015, section 3.1.1), as the
// supervisor generates it on the RT thread:
//
//   r(t) = w + s(⌊(t − t0)/Ts⌋)   for t0 <= t < t0 + D,   then r = w
//
// with w the working point, Ts the switching time, D the duration and s(k) the k-th level of the
// seeded PRMS or PRBS (control/excitation_sequence.hpp). The sequence is drawn once per switching
// time (its sample period is Ts, so each next() is one level), and the level in effect is chosen
// by the cycle's time, not by counting calls: the switches fall on t0 + k·Ts to the base tick
// whatever the loop rates, and a late cycle catches up on the levels it missed. For the same seed
// the levels are those of a sequence sampled every loop period (tests/analyze/identification_run.hpp
// samples it at 1 ms): a draw happens once per switching time in both.
//
// start() checks what the sequence's constructor would throw on, so nothing throws on the RT
// thread; the checks against the axis (limits, stability) are the operator thread's
// (daemon/hsad/excitation_gate.hpp). No allocation, no lock.
#pragma once

#include <cstdint>

#include "control/excitation_sequence.hpp"
#include "daemon/supervisor/command.hpp"

namespace hsa::daemon {

class ExcitationRun {
 public:
  ExcitationRun();

  // Starts a run at t_ns; false (and nothing starts) for parameters the sequence refuses.
  bool start(const ExcitationRequest& request, std::int64_t t_ns) noexcept;
  void stop() noexcept { active_ = false; }

  [[nodiscard]] bool active() const noexcept { return active_; }
  // The run's duration has passed at t_ns (only meaningful while active).
  [[nodiscard]] bool over(std::int64_t t_ns) const noexcept { return t_ns - start_ns_ >= duration_ns_; }
  // w + s(k) for the level in effect at t_ns (t_ns never decreases between calls).
  [[nodiscard]] double setpoint(std::int64_t t_ns) noexcept;
  [[nodiscard]] double working_point_m() const noexcept { return request_.working_point_m; }
  [[nodiscard]] double kp_per_m() const noexcept { return request_.kp_per_m; }

 private:
  ExcitationRequest request_{};
  control::ExcitationSequence sequence_;
  bool active_ = false;
  std::int64_t start_ns_ = 0;
  std::int64_t duration_ns_ = 0;
  std::int64_t switch_ns_ = 1;
  std::int64_t levels_drawn_ = 0;  // levels taken from the sequence so far
  double offset_ = 0.0;            // the level in effect
};

}  // namespace hsa::daemon
