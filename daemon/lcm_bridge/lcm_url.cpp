#include "daemon/lcm_bridge/lcm_url.hpp"

#include <arpa/inet.h>

#include <charconv>
#include <stdexcept>

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

std::optional<UdpmAddress> udpm_address(std::string_view url) {
  constexpr std::string_view scheme = "udpm://";
  if (url.empty()) url = kFallbackLcmUrl;
  if (!url.starts_with(scheme)) return std::nullopt;
  std::string_view rest = url.substr(scheme.size());
  rest = rest.substr(0, rest.find('?'));
  const std::size_t colon = rest.rfind(':');
  UdpmAddress out{std::string(rest.substr(0, colon)), 7667};
  in_addr parsed{};
  if (inet_pton(AF_INET, out.group.c_str(), &parsed) != 1) {
    throw std::invalid_argument("LCM URL '" + std::string(url) + "': '" + out.group + "' is not an IPv4 address");
  }
  // One spelling per group, so that equal addresses compare equal.
  char canonical[INET_ADDRSTRLEN] = {};
  out.group = inet_ntop(AF_INET, &parsed, canonical, sizeof canonical);
  if (colon == std::string_view::npos) return out;
  unsigned value = 0;
  const std::string_view digits = rest.substr(colon + 1);
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc{} || end != digits.data() + digits.size() || value == 0 || value > 65535) {
    throw std::invalid_argument("LCM URL '" + std::string(url) + "': bad port '" + std::string(digits) + "'");
  }
  out.port = static_cast<std::uint16_t>(value);
  return out;
}

}  // namespace hsa::daemon
