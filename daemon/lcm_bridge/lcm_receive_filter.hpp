// A kernel-side size limit on what reaches LCM's receive sockets.
//
// LCM 1.3.1 reassembles fragmented messages (magic "LC03") in buffers of the size the first
// fragment's header claims, up to 256 MiB each (LCM_MAX_MESSAGE_SIZE), and keeps one per sender
// address until 16 MiB of them are stored. A forged header therefore makes the LCM thread
// allocate, and with mlockall(MCL_FUTURE) commit and lock, hundreds of megabytes. hsad receives
// only small messages (setpoint_t and command_t are well under a kilobyte, sent unfragmented as
// "LC02" datagrams), so it never needs reassembly: a classic BPF socket filter on LCM's receive
// socket passes only datagrams that start with the "LC02" magic and are no longer than
// `max_datagram` bytes. Everything else is dropped by the kernel, before LCM sees it (counted in
// the socket's drops, /proc/net/udp), so a forged fragment or an oversized datagram costs hsad
// no memory at all.
//
// The filter must be on a socket before the socket can receive: LCM's receive thread reads from
// the moment it starts, inside the subscription. lcm_socket_guard.hpp attaches it when LCM binds
// the socket; receive_sockets() lets the bridge check that every socket on the port has it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hsa::daemon {

// 1,400 bytes: under LCM's short-message limit for a 1,500-byte MTU, and far above hsad's
// largest inbound message.
inline constexpr std::size_t kMaxInboundDatagram = 1400;

// Attaches the filter to the UDP socket `fd`. Returns 0, or the errno of the refusal. Any thread;
// allocates nothing, so it may run inside bind() (lcm_socket_guard.hpp).
int attach_receive_filter(int fd, std::size_t max_datagram = kMaxInboundDatagram) noexcept;

// Whether `fd` carries exactly the filter attach_receive_filter(fd, max_datagram) attaches.
[[nodiscard]] bool has_receive_filter(int fd, std::size_t max_datagram = kMaxInboundDatagram);

// This process's IPv4 datagram sockets bound to `port` (found in /proc/self/fd), and how many of
// them carry the filter.
struct ReceiveSockets {
  std::size_t bound = 0;
  std::size_t filtered = 0;
};
[[nodiscard]] ReceiveSockets receive_sockets(std::uint16_t port, std::size_t max_datagram = kMaxInboundDatagram);

}  // namespace hsa::daemon
