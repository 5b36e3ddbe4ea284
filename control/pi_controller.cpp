#include "control/pi_controller.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

namespace hsa::control {

namespace {

double dead_zone(double error, double width) {
  if (error > width) return error - width;
  if (error < -width) return error + width;
  return 0.0;
}

}  // namespace

PiController::PiController(const PiParams& params) : params_(params) {
  // Written as negated comparisons so that NaN is rejected too.
  if (!(params.period_s > 0.0)) throw std::invalid_argument("PiController: period must be > 0");
  if (!(params.output_limit > 0.0)) throw std::invalid_argument("PiController: output limit must be > 0");
  if (!(params.kp >= 0.0) || !(params.ki >= 0.0))
    throw std::invalid_argument("PiController: gains must be >= 0");
  if (!(params.max_setpoint_rate_m_s > 0.0))
    throw std::invalid_argument("PiController: setpoint rate limit must be > 0");
  if (!(params.dead_band_m >= 0.0)) throw std::invalid_argument("PiController: dead band must be >= 0");
  if (!(params.integral_dead_band_m >= 0.0))
    throw std::invalid_argument("PiController: integral dead band must be >= 0");
  for (const double k : {params.velocity_feedforward, params.acceleration_feedforward, params.jerk_feedforward}) {
    if (!(k >= 0.0) || !std::isfinite(k))
      throw std::invalid_argument("PiController: feed-forward gains must be finite and >= 0");
  }
  const FeedforwardSchedule& schedule = params.feedforward_schedule;
  has_feedforward_ = !schedule.empty() || params.velocity_feedforward != 0.0 ||
                     params.acceleration_feedforward != 0.0 || params.jerk_feedforward != 0.0;
  if (schedule.count > FeedforwardSchedule::kMaxPoints)
    throw std::invalid_argument("PiController: feed-forward schedule has too many points");
  for (std::size_t i = 0; i < schedule.count; ++i) {
    const FeedforwardSchedule::Point& p = schedule.points[i];
    for (const double k : {p.gains.velocity, p.gains.accel, p.gains.jerk}) {
      if (!(k >= 0.0) || !std::isfinite(k))
        throw std::invalid_argument("PiController: feed-forward schedule gains must be finite and >= 0");
    }
    if (!std::isfinite(p.position_m) || (i > 0 && !(p.position_m > schedule.points[i - 1].position_m)))
      throw std::invalid_argument("PiController: feed-forward schedule positions must increase");
  }
}

// The schedule's gains at the rate-limited setpoint, interpolated again only when it moved: at
// rest (most PI samples) the search over the points and the division are not repeated. The same
// position (bit for bit) gives the same gains, so the cache changes no output.
FeedforwardGains PiController::feedforward_gains() noexcept {
  const FeedforwardSchedule& schedule = params_.feedforward_schedule;
  if (schedule.empty())
    return {params_.velocity_feedforward, params_.acceleration_feedforward, params_.jerk_feedforward};
  const auto position_bits = std::bit_cast<std::uint64_t>(limited_setpoint_);
  if (!scheduled_valid_ || position_bits != scheduled_position_bits_) {
    scheduled_gains_ = schedule.at(limited_setpoint_);
    scheduled_position_bits_ = position_bits;
    scheduled_valid_ = true;
  }
  return scheduled_gains_;
}

void PiController::activate(double measured_position_m, double current_output) noexcept {
  const double limit = params_.output_limit;
  limited_setpoint_ = measured_position_m;
  integral_ = std::clamp(current_output, -limit, limit);
  error_ = 0.0;
  feedforward_ = 0.0;
  output_ = integral_;
  saturated_ = false;
}

bool PiController::set_gains(double kp, double ki) noexcept {
  if (!(kp >= 0.0) || !(ki >= 0.0) || !std::isfinite(kp) || !std::isfinite(ki)) return false;
  params_.kp = kp;
  params_.ki = ki;
  // The output of the last sample, re-solved for the integral with the new Kp.
  integral_ = output_ - kp * error_ - feedforward_;
  saturated_ = false;
  return true;
}

double PiController::update(double setpoint_m, double measured_position_m, const SetpointMotion& motion,
                            std::uint64_t periods) noexcept {
  const double limit = params_.output_limit;
  // The time since the last sample; one period (the usual case) needs no conversion, as
  // period_s · 1.0 is period_s exactly.
  const double dt = periods <= 1 ? params_.period_s : params_.period_s * static_cast<double>(periods);
  const double max_step = params_.max_setpoint_rate_m_s * dt;  // inf stays inf
  limited_setpoint_ += std::clamp(setpoint_m - limited_setpoint_, -max_step, max_step);

  error_ = dead_zone(limited_setpoint_ - measured_position_m, params_.dead_band_m);

  // A gain of 0 means no term at all, whatever the caller passes; without any, the opening is
  // feedforward_opening()'s 0.0 without looking at the gains.
  double feedforward = 0.0;
  if (has_feedforward_) feedforward = feedforward_opening(feedforward_gains(), motion);
  feedforward_ = feedforward;
  const double proportional = params_.kp * error_;
  const double integrated =
      integral_ + params_.ki * dt * dead_zone(error_, params_.integral_dead_band_m);
  const double candidate = proportional + feedforward + integrated;
  const bool pushes_up = candidate > limit && error_ > 0.0;
  const bool pushes_down = candidate < -limit && error_ < 0.0;
  if (!pushes_up && !pushes_down && !(motion.planned && params_.hold_integral_while_planned)) integral_ = integrated;

  const double unclamped = proportional + feedforward + integral_;
  output_ = std::clamp(unclamped, -limit, limit);
  saturated_ = std::abs(unclamped) > limit;
  if (saturated_) ++saturation_count_;
  return output_;
}

}  // namespace hsa::control
