// hsa-simdev's CAN side (--can IFACE): the simulated rig's encoder and valve electronics on a
// Linux CAN interface, so the real socketcan driver plugin can close the loop on it.
//
// Frames, classic CAN, little-endian, standard ids:
//   0x181  rig → controller   4 bytes  int32  rod position, 1 µm per count; sent every period
//                                            (not while the encoder is disconnected: the
//                                            controller then sees its frame go stale)
//   0x201  controller → rig   3 bytes  int16  valve command, 1e-4 per count (servo-valve: the
//                                            opening in [-1, 1]; proportional: the current, A)
//                                      uint8  valve enable (byte 2; nonzero = on)
//   0x281  rig → controller   2 bytes  uint8  status bits: bit 0 = communication watchdog
//                                            tripped (latched); sent every period
//                                      uint8  watchdog trips since start, modulo 256
// Communication watchdog (--watchdog-ms, rig_runner.hpp): once a 0x201 frame has arrived, each
// received 0x201 frame feeds it (a frame of the wrong length does not). No 0x201 frame for the
// watchdog time: the valve command goes to 0 and the enable off, latched, and 0x201 frames are
// held at that until one arrives with its enable byte 0, which clears the latch; a later frame
// with the enable on powers the valve again.
// Once a 0x201 frame has arrived, CAN drives the valve command and enable, and the Modbus
// holding register and coil no longer do. A 0x201 frame of another length is ignored (and
// counted).
//
// It reuses the socketcan plugin's own parts (settings, codec, frame bookkeeping, socket), with
// the rig's side of the map written as the plugin's settings: so the frame layout is checked by
// the same code, and a kernel without CAN or a missing interface gets the same clear message.
// One thread: send the position frame, drain the socket, sleep to the next period.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "tools/hsa_simdev/rig_runner.hpp"

namespace hsa::io::socketcan {
class CanSocket;
class FrameExchange;
}  // namespace hsa::io::socketcan

namespace hsa::simdev {

namespace can_id {
inline constexpr std::uint32_t position = 0x181;
inline constexpr std::uint32_t valve = 0x201;
inline constexpr std::uint32_t status = 0x281;
}  // namespace can_id

class CanServer {
 public:
  // Opens the socket on `interface`. Throws std::runtime_error with the reason.
  CanServer(RigRunner& rig, const std::string& interface, double period_s);
  ~CanServer();  // stops the thread
  CanServer(const CanServer&) = delete;
  CanServer& operator=(const CanServer&) = delete;

  void start();
  void stop();

  [[nodiscard]] std::uint64_t frames_sent() const { return sent_.load(std::memory_order_relaxed); }
  // Cycles in which a new valve frame was applied (several frames in one period count once).
  [[nodiscard]] std::uint64_t commands_applied() const { return applied_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t length_errors() const { return length_errors_.load(std::memory_order_relaxed); }

 private:
  void run(std::stop_token stop);

  RigRunner& rig_;
  double period_s_;
  std::unique_ptr<io::socketcan::FrameExchange> exchange_;
  std::unique_ptr<io::socketcan::CanSocket> socket_;
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> applied_{0};
  std::atomic<std::uint64_t> length_errors_{0};
  std::jthread thread_;
};

}  // namespace hsa::simdev
