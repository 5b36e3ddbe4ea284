// Gaps in each sender's `seq`, counted per sender (the message's operator_id), so that senders
// that share a channel do not make one another's numbering look like lost messages.
//
// One SeqGapCounter per sender; an operator id is a name an authenticated sender cannot forge, and
// one an unauthenticated daemon (require_auth = false) takes as given, so unsigned senders that
// leave it empty share one counter. The table is bounded: past kMaxSenders the sender heard from
// least recently is forgotten, and its next message starts it afresh without counting, as a
// restart does. It allocates when it meets a new sender: the LCM thread owns it, never the RT one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/lcm_bridge/seq_gap_counter.hpp"

namespace hsa::daemon {

class SenderSeqGaps {
 public:
  static constexpr std::size_t kMaxSenders = 16;

  // The number of `sender`'s messages missing before this one.
  std::uint64_t observe(std::string_view sender, std::int64_t seq) {
    ++clock_;
    Sender* s = find(sender);
    if (s == nullptr) s = &make_room_for(sender);
    s->last_heard = clock_;
    return s->gaps.observe(seq);
  }

 private:
  struct Sender {
    std::string id;
    SeqGapCounter gaps;
    std::uint64_t last_heard = 0;
  };

  Sender* find(std::string_view id) {
    for (Sender& s : senders_)
      if (s.id == id) return &s;
    return nullptr;
  }

  Sender& make_room_for(std::string_view id) {
    if (senders_.size() < kMaxSenders) return senders_.emplace_back(Sender{std::string(id), {}, 0});
    Sender* oldest = &senders_.front();
    for (Sender& s : senders_)
      if (s.last_heard < oldest->last_heard) oldest = &s;
    *oldest = Sender{std::string(id), {}, 0};
    return *oldest;
  }

  std::vector<Sender> senders_;
  std::uint64_t clock_ = 0;
};

}  // namespace hsa::daemon
