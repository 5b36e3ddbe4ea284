// The Moog E050 servo-valve of Puglisi et al. (2015, section 3.3: two-stage, closed centre, 350 Hz
// bandwidth), seen from the cylinder as its normalized spool opening x ∈ [−1, 1]:
//
//   ẍ + 2ζω·ẋ + ω²·x = ω²·u,   ω = 2π·350 rad/s,
//
// where u is the opening command. The paper neglects these dynamics next to the piston's
// (section 2); the simulator keeps them because a 350 Hz lag is what a 1 kHz loop actually sees.
// The spool's travel ends at ±1.
#pragma once

#include <numbers>

namespace hsa::sim {

struct ServoValveParameters {
  double bandwidth_hz = 350.0;
  double damping_ratio = 0.7;

  friend bool operator==(const ServoValveParameters&, const ServoValveParameters&) = default;
};

class ServoValve {
 public:
  explicit ServoValve(const ServoValveParameters& parameters) : parameters_(parameters) {}

  void reset(double opening) {
    opening_ = opening;
    rate_ = 0.0;
  }
  void set_stuck(bool stuck) { stuck_ = stuck; }
  void step(double command, double dt);

  [[nodiscard]] double opening() const { return opening_; }

 private:
  ServoValveParameters parameters_;
  double opening_ = 0.0;
  double rate_ = 0.0;  // 1/s
  bool stuck_ = false;
};

}  // namespace hsa::sim
