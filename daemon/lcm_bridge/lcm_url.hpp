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

}  // namespace hsa::daemon
