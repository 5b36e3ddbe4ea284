// Bounds on the cylinder PI's gains that an operator may set while an axis runs (GAINS commands,
// AxisLoop::request_params). The configured gains lie within them. Where a configuration does not
// give them they default to a small multiple of the configured gains, so no axis runs unbounded
// and the operator can retune by up to that factor without a restart.
#pragma once

#include "control/pi_controller.hpp"

namespace hsa::daemon {

struct GainBounds {
  double max_kp = 0.0;  // m⁻¹; a runtime kp must be in (0, max_kp]
  double max_ki = 0.0;  // m⁻¹s⁻¹; a runtime ki must be in [0, max_ki]
};

inline constexpr double kDefaultGainBoundFactor = 2.0;

inline GainBounds default_gain_bounds(const control::PiParams& configured) {
  return {kDefaultGainBoundFactor * configured.kp, kDefaultGainBoundFactor * configured.ki};
}

}  // namespace hsa::daemon
