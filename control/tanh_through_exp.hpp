#pragma once

#include <cmath>

namespace hsa::control {

// tanh(y) = sign(y)·(1 − e)/(1 + e), e = exp(−2|y|): one exp and one division.
//
// Why not std::tanh: glibc evaluates it through expm1, which costs about 1.6 times an exp; in the
// valve law's K_p(e) (valve_law.hpp) it was a quarter of the whole 10 kHz control tick. The form
// here loses the relative precision of tanh near 0 (1 − e cancels), but not the absolute one: it
// stays within 2.3e-16 of std::tanh everywhere (tests/control/test_tanh_through_exp.cpp), and the
// law multiplies it by a current of about 0.1 A. Like std::tanh it is exactly ±1 for large |y|,
// and passes NaN through.
[[nodiscard]] inline double tanh_through_exp(double y) noexcept {
  // Past 19.1, 1 − tanh(y) < 2^−54 and tanh rounds to ±1: skip the exp, as glibc does past 22.
  if (std::fabs(y) > 19.1) return std::copysign(1.0, y);
  const double e = std::exp(-2.0 * std::fabs(y));
  return std::copysign((1.0 - e) / (1.0 + e), y);
}

}  // namespace hsa::control
