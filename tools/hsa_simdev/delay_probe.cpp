#include "tools/hsa_simdev/delay_probe.hpp"

namespace hsa::simdev {

DelayProbe::DelayProbe(const DelayProbeSettings& settings) : settings_(settings), offset_(-settings.step_m / 2) {
  delays_ns_.reserve(settings_.capacity);
}

std::int64_t DelayProbe::next_jitter() {
  if (settings_.jitter_ns <= 0) return 0;
  lcg_ = lcg_ * 6364136223846793005ull + 1442695040888963407ull;  // Knuth's MMIX constants
  return static_cast<std::int64_t>((lcg_ >> 33) % static_cast<std::uint64_t>(settings_.jitter_ns + 1));
}

double DelayProbe::offset_at_tick(std::int64_t now_ns) {
  if (!started_) {
    if (!loop_closed_) return offset_;
    started_ = true;  // the loop settles on the low level before the first edge
    next_edge_ns_ = now_ns + settings_.hold_ns + next_jitter();
    return offset_;
  }
  if (now_ns < next_edge_ns_) return offset_;
  if (waiting_) ++misses_;  // no reaction within hold: a lost write, or a loop that is off
  offset_ = -offset_;
  direction_ = offset_ > 0.0 ? -1.0 : 1.0;
  edge_ns_ = now_ns;
  waiting_ = true;
  ++edges_;
  next_edge_ns_ = now_ns + settings_.hold_ns + next_jitter();
  return offset_;
}

void DelayProbe::on_command(double command, std::int64_t now_ns) {
  const double change = have_command_ ? command - last_command_ : 0.0;
  const double previous = last_command_;
  have_command_ = true;
  last_command_ = command;
  if (command != 0.0) loop_closed_ = true;
  if (!waiting_ || change * direction_ < settings_.threshold) return;
  // Taken before the edge (a server thread stamps its request before the rig's lock, which the
  // edge may win): computed from an older sample, whatever it changed.
  if (now_ns < edge_ns_) return;
  // To or from the safe value: the loop opened (a fault, the axis disabled) or closed again (an
  // enable), a jump of its own that says nothing of the edge.
  if (command == 0.0 || previous == 0.0) return;
  waiting_ = false;
  if (delays_ns_.size() < settings_.capacity) delays_ns_.push_back(now_ns - edge_ns_);
}

}  // namespace hsa::simdev
