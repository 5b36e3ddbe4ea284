// The checks an operator's CAPTURE command (command_t.CAPTURE, `hsactl capture`) passes on the
// operator thread before the RT thread takes it, and what it resolves for it: the signal's index in
// the recorder row's table (recorder_signals.hpp) and the lengths in rows of the axis's ring.
//
// Lengths: pre_s before the trigger row and post_s after it, rounded to base ticks, must fit the
// ring with the trigger row: pre + 1 + post <= the ring's rows ([axes.recorder] seconds). Unset
// (negative) post_s is the ring's post_trigger_s; unset pre_s is what the ring holds besides
// (the whole ring). A condition names a signal of the capture file (recorder_row.hpp) and a finite
// level. A refusal names what is wrong and the bound; the request then changes nothing.
#pragma once

#include <cstddef>
#include <string>

#include "daemon/supervisor/capture_request.hpp"

namespace hsa::daemon {

struct CaptureRingShape {
  std::size_t rows = 0;       // the ring's capacity
  std::size_t post_rows = 0;  // its default post-trigger rows
  double rate_hz = 0.0;       // rows per second (the base rate)
};

namespace capture_gate {

// "" and `request` resolved (signal_index, pre_rows, post_rows), or why it is refused (`request`
// unchanged).
[[nodiscard]] std::string resolve(CaptureRequest& request, const CaptureRingShape& ring);

}  // namespace capture_gate
}  // namespace hsa::daemon
