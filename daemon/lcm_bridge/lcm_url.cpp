#include "daemon/lcm_bridge/lcm_url.hpp"

namespace hsa::daemon {

std::string lcm_url_with_recv_buf(std::string_view url, std::size_t recv_buf_size) {
  std::string out(url.empty() ? kFallbackLcmUrl : url);
  if (!out.starts_with("udpm://")) return out;
  const auto query = out.find('?');
  if (query != std::string::npos) {
    // Match the option name at the start of a key, not inside another key or a value.
    const std::string_view options = std::string_view(out).substr(query);
    for (std::size_t at = 0; at != std::string_view::npos; at = options.find('&', at + 1)) {
      if (options.substr(at + 1).starts_with("recv_buf_size=")) return out;
    }
  }
  out += (query == std::string::npos) ? '?' : '&';
  out += "recv_buf_size=" + std::to_string(recv_buf_size);
  return out;
}

}  // namespace hsa::daemon
