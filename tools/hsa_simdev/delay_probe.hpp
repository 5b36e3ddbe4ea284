// hsa-simdev's sensor-to-actuator delay probe (--delay-probe): how long, on the device's own clock,
// from the encoder sample that first shows a step to the first valve command that reacts to it.
//
// Why a step and not a tag: a tag (a sequence number in a register, echoed in the command) would
// have to cross hsad's control law, which computes an opening from a position and has nowhere to
// carry anything else; hsad's plugin ABI has no field for it either. A step needs nothing of hsad:
// the device adds a square wave to the position it serves, and the closed loop's proportional
// term turns each edge into a jump of the valve command of -Kp·step (a PI law u = Kp·e + i with
// e = r - y: the position up, the command down), while between edges the command moves only by
// what the integral and the rod's own motion add per write (Ki·e·T, Kp·ẏ·T: thousandths of an
// opening at hsad's example gains). So the first command whose change from the command before it
// is at least `threshold` in the edge's direction is, exactly, the first one computed from a
// sample that shows the edge; no other write can pass the threshold, no reacting one can miss it.
//
// Algorithm (the caller passes every time, on one monotonic clock; no clock, no lock, no I/O here):
//   The probe starts at the first nonzero command: until then the loop is not closed (hsad's
//   plugins write the safe value, 0, while the axis is not enabled), and edges would only miss.
//   offset_at_tick(now): the rig's thread, for each new sample, before it is served. When the
//     next edge is due and no edge waits for its reaction, the offset flips between -step/2 and
//     +step/2 (zero mean: the loop keeps the real rod where it was) and the edge's time is `now`,
//     the time of the first sample that shows it. An edge is due `hold` after the previous one
//     plus a pseudo-random 0..`jitter` (a fixed-seed LCG), so the edges fall at every phase of the
//     bus cycle instead of locking to it. An edge still waiting after `hold` is a miss.
//   on_command(u, now): every valve command the master wrote (Modbus: a write of the command
//     registers; CAN: a valve frame applied), at the time the device took it. The delay of the
//     waiting edge is now - its time when (u - u_previous)·direction >= threshold, direction -1
//     for an edge up, +1 for an edge down. Not a reaction, whatever its change: a command taken
//     before the edge's time (its request was stamped before the edge won the rig's lock), and a
//     change to or from exactly 0, the plugins' safe value (the loop opening on a fault or closing
//     again on an enable: a jump of its own). hsad's PI gives exactly 0.0 no other way.
// Delays are kept up to `capacity` (reserved at construction): no allocation afterwards.
#pragma once

#include <cstdint>
#include <vector>

namespace hsa::simdev {

struct DelayProbeSettings {
  double step_m = 0.002;        // peak-to-peak of the square wave added to the served position
  std::int64_t hold_ns = 20'000'000;   // between edges, at least; must exceed the longest delay
  std::int64_t jitter_ns = 3'000'000;  // plus 0..jitter, pseudo-random
  double threshold = 0.05;      // command change that marks the reaction (see above)
  std::size_t capacity = 100'000;
};

class DelayProbe {
 public:
  explicit DelayProbe(const DelayProbeSettings& settings);

  // The rig's thread: the offset to add to the position sample taken at `now_ns`.
  double offset_at_tick(std::int64_t now_ns);
  // A valve command the device took at `now_ns`.
  void on_command(double command, std::int64_t now_ns);

  [[nodiscard]] const std::vector<std::int64_t>& delays_ns() const { return delays_ns_; }
  [[nodiscard]] std::uint64_t edges() const { return edges_; }
  [[nodiscard]] std::uint64_t misses() const { return misses_; }
  [[nodiscard]] const DelayProbeSettings& settings() const { return settings_; }

 private:
  std::int64_t next_jitter();

  DelayProbeSettings settings_;
  double offset_ = 0.0;
  bool loop_closed_ = false;  // a nonzero command has arrived
  bool started_ = false;
  bool waiting_ = false;
  double direction_ = 0.0;  // the reaction's sign: -1 after an edge up
  std::int64_t edge_ns_ = 0;
  std::int64_t next_edge_ns_ = 0;
  bool have_command_ = false;
  double last_command_ = 0.0;
  std::uint64_t lcg_ = 0x9E3779B97F4A7C15ull;
  std::uint64_t edges_ = 0;
  std::uint64_t misses_ = 0;
  std::vector<std::int64_t> delays_ns_;
};

}  // namespace hsa::simdev
