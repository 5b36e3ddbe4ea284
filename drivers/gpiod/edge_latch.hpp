// What an edge-event input (the e-stop) reports each cycle, so that a pulse shorter than a cycle
// is not lost between two reads.
//
// Algorithm. Every cycle the driver reads the line's level first and then drains the edge
// events the kernel queued since the last drain. If there was at least one edge and the level is
// back where it was last reported, the line went somewhere and came back between two reads: the
// latch reports the other value for this one cycle (the pulse, stretched to one cycle), and the
// level again from the next cycle on. Otherwise it reports the level.
//
// Why this shape:
// - It needs only the count of edges, not their direction. Linux's v1 GPIO interface, which
//   libgpiod 1.6 uses, fills in an event's rising/falling by reading the level in its interrupt
//   thread, after the edge: for a short pulse both events can say "rising".
// - Level first, events second: an edge that lands between the two is drained now and its new
//   level read next cycle, which is at worst a change seen one cycle early, never a change lost.
// - Symmetric: the driver does not need to know which level means "pressed"; any change the line
//   makes is seen for at least one cycle, and the daemon's `invert` decides what it means.
// The cost: if the kernel queues an edge's event only after a later cycle has already read the
// new level (interrupt thread held off for a whole cycle), that stale event shows as a one-cycle
// pulse back to the old value. For an e-stop that is a spurious "pressed" right after a release,
// while the fault from the press is still latched: never a missed press.
//
// Pure logic, no I/O: tested on any machine. noexcept and allocation-free: runs in read().
#pragma once

namespace hsa::io::gpiod {

class EdgeLatch {
 public:
  // Starts from `level`, the value read at configure.
  void reset(bool level) noexcept { reported_ = level; }

  // `level`: the line read this cycle; `edges`: events drained after that read. Returns the
  // value to report this cycle.
  bool update(bool level, unsigned int edges) noexcept {
    reported_ = (edges > 0 && level == reported_) ? !level : level;
    return reported_;
  }

  [[nodiscard]] bool reported() const noexcept { return reported_; }

 private:
  bool reported_ = false;
};

}  // namespace hsa::io::gpiod
