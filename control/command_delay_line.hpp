#pragma once

#include <array>
#include <cstddef>

namespace hsa::control {

// The valve's commands still on their way: Canuto et al. (2014) eq 1's regulator delay τ (plus
// the current-to-LVDT delay, as identified) in whole samples, for the models that run the
// identified valve (valve_time_optimal.hpp, valve_model_predictor.hpp). A fixed ring of at most
// kMaxSamples; nothing allocates.
class CommandDelayLine {
 public:
  static constexpr int kMaxSamples = 16;

  // `samples` in [0, kMaxSamples]; the caller has checked it.
  explicit CommandDelayLine(int samples = 0) noexcept : samples_(samples) {}

  [[nodiscard]] int samples() const noexcept { return samples_; }

  // Every pending command set to `current_a`: from rest on a held current.
  void fill(double current_a) noexcept {
    line_.fill(current_a);
    head_ = 0;
  }

  // `current_a` starts its δ samples of delay; returns the command δ ago, which enters the valve
  // now (`current_a` itself when δ = 0).
  double push(double current_a) noexcept {
    if (samples_ == 0) return current_a;
    const double entering = line_[static_cast<std::size_t>(head_)];
    line_[static_cast<std::size_t>(head_)] = current_a;
    head_ = (head_ + 1) % samples_;
    return entering;
  }

  // The k-th pending command, oldest first (k in [0, samples())): what enters after k more samples.
  [[nodiscard]] double pending(int k) const noexcept { return line_[static_cast<std::size_t>((head_ + k) % samples_)]; }

 private:
  int samples_;
  std::array<double, kMaxSamples> line_{};
  int head_ = 0;
};

}  // namespace hsa::control
