// hsa-simdev's communication watchdog: what a correctly configured Modbus coupler or drive
// amplifier does when its master falls silent (the PC's daemon killed, stopped or hung): after
// `timeout` with no master write it puts its outputs to their safe state and latches that, so that
// only the master, explicitly, can bring them back.
//
// Algorithm, on the device's own monotonic clock (the caller passes the times):
//   - feed(now): a master write arrived. The first one arms the watchdog: before it, the outputs
//     are at their power-on state (valve unpowered) and there is nothing to guard.
//   - check(now): called periodically by the device's own thread, whether or not requests arrive.
//     Armed, untripped and now - last feed > timeout: trip, latch, count. Returns true only on the
//     call that trips, so the caller puts its outputs safe exactly once per trip.
//   - acknowledge(): the master's explicit clear (hsa-simdev: the master writes the valve enable
//     off; see docs/drivers.md, "The simulated device"). Clears the latch; the timer restarts from that write.
// timeout 0 turns it off: never armed, never trips.
//
// No clock, no lock, no allocation: the owner (rig_runner.hpp) holds it under its mutex.
#pragma once

#include <cstdint>

namespace hsa::simdev {

class CommWatchdog {
 public:
  explicit CommWatchdog(std::int64_t timeout_ns = 0) : timeout_ns_(timeout_ns > 0 ? timeout_ns : 0) {}

  void feed(std::int64_t now_ns) {
    if (timeout_ns_ == 0) return;
    armed_ = true;
    last_feed_ns_ = now_ns;
  }

  bool check(std::int64_t now_ns) {
    if (!armed_ || tripped_ || now_ns - last_feed_ns_ <= timeout_ns_) return false;
    tripped_ = true;
    ++trips_;
    return true;
  }

  void acknowledge() { tripped_ = false; }

  [[nodiscard]] bool enabled() const { return timeout_ns_ != 0; }
  [[nodiscard]] bool armed() const { return armed_; }
  [[nodiscard]] bool tripped() const { return tripped_; }
  [[nodiscard]] std::uint64_t trips() const { return trips_; }
  [[nodiscard]] std::int64_t timeout_ns() const { return timeout_ns_; }

 private:
  std::int64_t timeout_ns_;
  bool armed_ = false;
  bool tripped_ = false;
  std::int64_t last_feed_ns_ = 0;
  std::uint64_t trips_ = 0;
};

}  // namespace hsa::simdev
