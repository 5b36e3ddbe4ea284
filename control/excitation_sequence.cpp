#include "control/excitation_sequence.hpp"

#include <cmath>
#include <stdexcept>

namespace hsa::control {

ExcitationSequence::ExcitationSequence(const ExcitationParams& params) : params_(params) {
  if (!std::isfinite(params.amplitude) || params.amplitude < 0.0)
    throw std::invalid_argument("excitation amplitude must be finite and >= 0");
  if (!(params.sample_period_s > 0.0) || !std::isfinite(params.sample_period_s))
    throw std::invalid_argument("excitation sample period must be positive");
  if (!(params.switching_time_s >= params.sample_period_s) || !std::isfinite(params.switching_time_s))
    throw std::invalid_argument("excitation switching time must be at least one sample period");
  if (params.kind == ExcitationKind::prms && params.levels < 2)
    throw std::invalid_argument("a PRMS needs at least 2 levels");
  if (params.max_hold_switches < 1) throw std::invalid_argument("max_hold_switches must be >= 1");
  samples_per_switch_ = std::lround(params.switching_time_s / params.sample_period_s);
  reset();
}

void ExcitationSequence::reset() noexcept {
  state_ = params_.seed;
  // The register must never be all zeros (it would stay there); a seed that maps to zero gets 1.
  lfsr_ = static_cast<std::uint32_t>(random() & 0x7FFFFFFFu);
  if (lfsr_ == 0) lfsr_ = 1;
  remaining_ = 0;
}

std::uint64_t ExcitationSequence::random() noexcept {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

void ExcitationSequence::draw() noexcept {
  if (params_.kind == ExcitationKind::prbs) {
    // Fibonacci LFSR, taps 31 and 28: period 2³¹ − 1 bits.
    const std::uint32_t bit = ((lfsr_ >> 30) ^ (lfsr_ >> 27)) & 1u;
    lfsr_ = ((lfsr_ << 1) | bit) & 0x7FFFFFFFu;
    value_ = bit ? params_.amplitude : -params_.amplitude;
    remaining_ = samples_per_switch_;
    return;
  }
  const auto levels = static_cast<std::uint64_t>(params_.levels);
  const auto level = static_cast<double>(random() % levels);
  value_ = params_.amplitude * (2.0 * level / static_cast<double>(levels - 1) - 1.0);
  const auto holds = static_cast<std::uint64_t>(params_.max_hold_switches);
  remaining_ = samples_per_switch_ * static_cast<long>(1 + random() % holds);
}

double ExcitationSequence::next() noexcept {
  if (remaining_ == 0) draw();
  --remaining_;
  return value_;
}

}  // namespace hsa::control
