#include "daemon/supervisor/excitation_run.hpp"

#include <cmath>

namespace hsa::daemon {

ExcitationRun::ExcitationRun() : sequence_(control::ExcitationParams{}) {}

bool ExcitationRun::start(const ExcitationRequest& request, std::int64_t t_ns) noexcept {
  // What ExcitationSequence's constructor refuses, and a duration it cannot time.
  const bool valid = std::isfinite(request.amplitude_m) && request.amplitude_m >= 0.0 &&
                     std::isfinite(request.switching_time_s) && request.switching_time_s >= 1e-6 &&
                     std::isfinite(request.duration_s) && request.duration_s > 0.0 &&
                     request.duration_s <= kMaxExcitationDurationS && std::isfinite(request.working_point_m) &&
                     std::isfinite(request.kp_per_m) && request.kp_per_m > 0.0 &&
                     (request.kind == control::ExcitationKind::prbs || request.levels >= 2);
  if (!valid) return false;
  request_ = request;
  control::ExcitationParams params;
  params.kind = request.kind;
  params.amplitude = request.amplitude_m;
  params.switching_time_s = request.switching_time_s;
  params.levels = request.kind == control::ExcitationKind::prms ? request.levels : 2;
  params.max_hold_switches = 1;
  params.seed = request.seed;
  params.sample_period_s = request.switching_time_s;  // one next() per level
  sequence_ = control::ExcitationSequence(params);   // checked above: does not throw
  start_ns_ = t_ns;
  duration_ns_ = std::llround(request.duration_s * 1e9);
  switch_ns_ = std::llround(request.switching_time_s * 1e9);
  levels_drawn_ = 0;
  offset_ = 0.0;
  active_ = true;
  return true;
}

double ExcitationRun::setpoint(std::int64_t t_ns) noexcept {
  const std::int64_t elapsed = t_ns > start_ns_ ? t_ns - start_ns_ : 0;
  const std::int64_t level = elapsed / switch_ns_;  // the level in effect: k = ⌊(t − t0)/Ts⌋
  while (levels_drawn_ <= level) {
    offset_ = sequence_.next();
    ++levels_drawn_;
  }
  return request_.working_point_m + offset_;
}

}  // namespace hsa::daemon
