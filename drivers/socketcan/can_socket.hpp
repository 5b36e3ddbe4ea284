// A raw CAN socket (PF_CAN, SOCK_RAW, CAN_RAW) opened for the socketcan plugin, with every way
// opening it can fail turned into a message an operator can act on.
//
// Steps, in this order so no unwanted frame is ever queued: socket (non-blocking) → receive
// filter: exactly the configured input ids (CAN_RAW_FILTER; none when there are no inputs) →
// all error classes (CAN_RAW_ERR_FILTER) → CAN FD frames when a frame needs them
// (CAN_RAW_FD_FRAMES, after checking the interface's MTU is CANFD_MTU) → bind to the interface.
//
// Failures throw CanSocketError:
//   - socket() refused with EAFNOSUPPORT: this kernel has no AF_CAN; the message names the
//     modules: can, can-raw, and can-dev with the interface's driver (or vcan);
//   - no interface of that name, an interface that is not CAN (its hardware type is not
//     ARPHRD_CAN), or one that is down: the message names it and says how to create it or
//     bring it up.
#pragma once

#include <stdexcept>
#include <string>

#include "drivers/socketcan/can_settings.hpp"

namespace hsa::io::socketcan {

class CanSocketError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The message for socket(PF_CAN, SOCK_RAW, CAN_RAW) failing with `error` (an errno).
std::string socket_failure_message(int error);

class CanSocket {
 public:
  // Throws CanSocketError.
  explicit CanSocket(const CanSettings& settings);
  ~CanSocket();
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;

  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

}  // namespace hsa::io::socketcan
