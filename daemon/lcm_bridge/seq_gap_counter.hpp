// Counts messages lost between a sender and the daemon from gaps in the sender's `seq`.
//
// LCM drops silently: a full subscription queue or socket buffer leaves no trace the API exposes.
// A sender that numbers its messages (+1 each) makes the loss visible at the receiver: a jump from
// 7 to 10 means two messages never arrived. One counter follows one sender (sender_seq_gaps.hpp
// keeps one per sender). A seq that does not increase means the sender restarted: the counter
// re-synchronises without counting, and so does an implausibly large jump, which is a restart
// with a different numbering rather than a million lost messages.
#pragma once

#include <cstdint>

namespace hsa::daemon {

class SeqGapCounter {
 public:
  static constexpr std::uint64_t kMaxPlausibleGap = std::uint64_t{1} << 20;

  // Returns the number of messages missing before this one.
  std::uint64_t observe(std::int64_t seq) {
    const bool first = !seen_;
    const std::int64_t last = last_;
    seen_ = true;
    last_ = seq;
    if (first || seq <= last) return 0;
    const std::uint64_t gap = static_cast<std::uint64_t>(seq) - static_cast<std::uint64_t>(last) - 1;
    return gap > kMaxPlausibleGap ? 0 : gap;
  }

 private:
  bool seen_ = false;
  std::int64_t last_ = 0;
};

}  // namespace hsa::daemon
