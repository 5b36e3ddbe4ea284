// A kernel-side size limit on what reaches LCM's receive socket.
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
// no memory at all. The RT thread's memory stays locked with MCL_FUTURE as before.
//
// LCM does not expose its receive socket; it is found by its bound port among this process's
// datagram sockets (/proc/self/fd), after the subscriptions that create it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace hsa::daemon {

// 1,400 bytes: under LCM's short-message limit for a 1,500-byte MTU, and far above hsad's
// largest inbound message.
inline constexpr std::size_t kMaxInboundDatagram = 1400;

// The UDP port of a udpm:// URL (LCM's default 7667 when it names none), or nothing for another
// provider, which has no socket.
[[nodiscard]] std::optional<std::uint16_t> udpm_port(std::string_view url);

// Attaches the filter to every IPv4 datagram socket of this process bound to `port`; returns how
// many it filtered. Throws std::runtime_error if the kernel refuses the filter.
std::size_t limit_lcm_receive(std::uint16_t port, std::size_t max_datagram = kMaxInboundDatagram);

}  // namespace hsa::daemon
