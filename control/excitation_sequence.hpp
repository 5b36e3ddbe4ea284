// Identification excitation for a closed position loop (Puglisi et al. 2015, section 3.1.1): a
// setpoint offset that changes level at random, so that "all the amplitudes and frequencies and all
// their combinations" are in the input while the rod stays near its working point.
//
// Two kinds, both sampled once per loop period by next():
// - PRMS, the paper's pseudo-random multi-level signal: every switching time the offset jumps to
//   one of `levels` values evenly spaced over [−amplitude, +amplitude], drawn uniformly (a new
//   level is always drawn, so it may repeat). With max_hold_switches = h > 1 each level is held for
//   a random whole number 1…h of switching times, which is the paper's random width (1–6 s as
//   1 s × h = 6). Its spectrum is that of a random telegraph signal: flat within a few dB up to
//   about 1/(2·switching time), first null at 1/switching time (for h = 1).
// - PRBS, the pseudo-random binary sequence: ±amplitude, one bit of a maximum-length 31-bit
//   linear feedback shift register (x³¹ + x²⁸ + 1) per switching time. Same spectral shape.
//
// The random numbers come from SplitMix64 (Steele, Lea, Flood 2014) seeded by `seed`, not from the
// standard library's distributions, whose results differ between implementations: the same seed
// gives the same sequence on every build. Nothing allocates after construction and next() is a few
// integer operations, so the RT cylinder loop can run it.
#pragma once

#include <cstdint>

namespace hsa::control {

enum class ExcitationKind { prms, prbs };

struct ExcitationParams {
  ExcitationKind kind = ExcitationKind::prms;
  double amplitude = 1e-3;         // the largest offset, in the setpoint's unit (m)
  double switching_time_s = 0.25;  // the shortest time between level changes
  int levels = 5;                  // PRMS only: >= 2 (PRBS always has 2)
  int max_hold_switches = 1;       // PRMS only: each level lasts 1…max_hold_switches switching times
  std::uint64_t seed = 1;
  double sample_period_s = 1e-3;   // how often next() is called (the cylinder loop's period)
};

class ExcitationSequence {
 public:
  // Throws std::invalid_argument for a non-finite or negative amplitude, a switching time shorter
  // than one sample period, fewer than 2 levels or a hold below 1 switching time.
  explicit ExcitationSequence(const ExcitationParams& params);

  // The offset for this sample; advances by one sample period.
  double next() noexcept;
  // Back to the first sample: the same sequence again.
  void reset() noexcept;

  [[nodiscard]] const ExcitationParams& params() const { return params_; }
  [[nodiscard]] long samples_per_switch() const { return samples_per_switch_; }

 private:
  std::uint64_t random() noexcept;  // SplitMix64
  void draw() noexcept;             // the next level and how long it lasts

  ExcitationParams params_;
  long samples_per_switch_;
  std::uint64_t state_ = 0;
  std::uint32_t lfsr_ = 1;
  double value_ = 0.0;
  long remaining_ = 0;  // samples left at value_
};

}  // namespace hsa::control
