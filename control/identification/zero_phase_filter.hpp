// The low-pass filter of Puglisi et al. (2015, section 3.1.1 and 3.4.1): a 4th-order Butterworth,
// used there at 400 Hz on the pressures and at 200 Hz on the finite-difference velocity and
// acceleration. Offline the filter is run forward and then backward over the record (zero phase):
// the paper's causal filters at two cut-offs delay the two sides of eq 34 by different amounts
// (about 1 ms at 400 Hz, 2 ms at 200 Hz: 0.1 rad of the 17 Hz mode), which biases m and σ; run
// both ways, neither side is delayed. The magnitude is the Butterworth's squared (−6 dB at f_c).
//
// Design: two biquads with the Butterworth's pole quality factors 1/(2·cos(π/8)) and
// 1/(2·cos(3π/8)), each by the bilinear transform with the cut-off pre-warped (the RBJ audio-EQ
// cookbook's low-pass), so f_c is exact at the sample rate. Each pass starts from the record's
// end value in steady state, so a record that does not start at zero rings nothing in.
#pragma once

#include <vector>

namespace hsa::control::identification {

// Throws std::invalid_argument unless 0 < cutoff_hz < sample_rate_hz / 2.
[[nodiscard]] std::vector<double> butterworth4_zero_phase(const std::vector<double>& x, double cutoff_hz,
                                                          double sample_rate_hz);

}  // namespace hsa::control::identification
