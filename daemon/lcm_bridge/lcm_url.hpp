// The LCM URL the bridge opens: the configured one with a deliberate socket receive buffer.
//
// LCM's udpm provider takes the kernel's default receive buffer unless the URL names
// `recv_buf_size`; at 10 kHz of setpoints that default overflows whenever the LCM thread is
// descheduled for a few milliseconds. So the bridge adds `recv_buf_size=N` to a udpm URL that
// does not set it. A URL that sets it is left alone (the operator decided), and so are other
// providers (memq://, file://), which have no socket. The kernel caps the request at
// net.core.rmem_max (LCM warns when it gets less); deployments raise that sysctl.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace hsa::daemon {

// Used for an empty URL. Multicast on the host only (ttl=0): the daemon's traffic does not leave
// the machine unless the configuration says so. (The configuration's own default is the same.)
inline constexpr std::string_view kFallbackLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// 2 MiB: about 2,500 small datagrams (the kernel charges ~800 B per skb), a quarter of a second
// of setpoints at 10 kHz.
inline constexpr std::size_t kDefaultRecvBufSize = std::size_t{2} << 20;

// An empty URL means kFallbackLcmUrl.
[[nodiscard]] std::string lcm_url_with_recv_buf(std::string_view url, std::size_t recv_buf_size);

// Where a udpm:// URL sends and receives: its multicast group (dotted quad, as written) and its UDP
// port (LCM's default 7667 when it names none). The options after '?' (ttl, recv_buf_size) are not
// part of it: two URLs that differ only there are the same network.
struct UdpmAddress {
  std::string group;
  std::uint16_t port = 0;
  friend bool operator==(const UdpmAddress&, const UdpmAddress&) = default;
};

// The address of a udpm:// URL (an empty URL means kFallbackLcmUrl), or nothing for another
// provider (memq://, file://), which has no socket. Throws std::invalid_argument for a udpm URL
// whose group is not an IPv4 address or whose port is not a number in [1, 65535].
[[nodiscard]] std::optional<UdpmAddress> udpm_address(std::string_view url);

}  // namespace hsa::daemon
