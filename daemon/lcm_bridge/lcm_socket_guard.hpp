// Puts the receive filter (lcm_receive_filter.hpp) on LCM's receive sockets before they can
// receive.
//
// LCM 1.3.1's udpm provider creates its receive socket inside the first subscription, binds it to
// the group's port, joins the group, starts the thread that reads it and runs a self-test, all
// before lcm_subscribe returns, and it never hands the socket out. A filter attached after the
// subscription comes too late: whatever arrived in between has been read, and a forged fragment
// header among it has made LCM reserve the 256 MiB the header claims. A UDP socket receives
// nothing before it is bound, so the filter goes on in bind().
//
// How: this unit defines `bind`. Its object file is linked into every executable that builds an
// LcmBridge (the bridge's constructor refers to it), and the definition in the executable
// interposes on liblcm's call to the C library's bind (ELF symbol lookup: the executable comes
// first). While an LcmSocketGuard is armed for a port, a bind of an IPv4 datagram socket to that
// port first attaches the filter, then binds; if the kernel refuses the filter, the bind fails
// with its errno (LCM's subscription fails, and the bridge refuses to start). Every other bind goes
// straight to the kernel. verify() checks the outcome (every socket on the port carries the
// filter), so a build in which the interposition did not take cannot start with the door open.
#pragma once

#include <cstdint>

namespace hsa::daemon {

class LcmSocketGuard {
 public:
  // Arms the guard for `port` (several guards, also on several ports, may be armed at once).
  // Throws std::runtime_error when more ports than the guard keeps are armed.
  explicit LcmSocketGuard(std::uint16_t port);
  ~LcmSocketGuard();
  LcmSocketGuard(const LcmSocketGuard&) = delete;
  LcmSocketGuard& operator=(const LcmSocketGuard&) = delete;

  // Throws std::runtime_error unless this process has a socket bound to the port and every one
  // of them carries the receive filter. Call after the subscriptions that create LCM's sockets.
  void verify() const;

 private:
  std::uint16_t port_;
};

}  // namespace hsa::daemon
