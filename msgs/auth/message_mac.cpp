#include "msgs/auth/message_mac.hpp"

#include <sodium.h>

namespace hsa::msgs {

static_assert(crypto_auth_hmacsha256_BYTES == kMacBytes);
static_assert(crypto_auth_hmacsha256_KEYBYTES == kKeyBytes);

namespace {

// libsodium asks for sodium_init() before any other call; it is idempotent, and done once here.
[[maybe_unused]] const bool g_sodium_ready = sodium_init() >= 0;

}  // namespace

Mac message_mac(const Key& key, std::string_view channel, const void* covered, std::size_t covered_size) {
  crypto_auth_hmacsha256_state state;
  crypto_auth_hmacsha256_init(&state, key.data(), key.size());
  const unsigned char separator = 0;
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(channel.data()), channel.size());
  crypto_auth_hmacsha256_update(&state, &separator, 1);
  crypto_auth_hmacsha256_update(&state, static_cast<const unsigned char*>(covered), covered_size);
  Mac mac;
  crypto_auth_hmacsha256_final(&state, mac.data());
  sodium_memzero(&state, sizeof state);
  return mac;
}

bool mac_matches(const Key& key, std::string_view channel, const void* encoded, std::size_t size) {
  if (encoded == nullptr || size < kMacBytes) return false;
  const auto* bytes = static_cast<const unsigned char*>(encoded);
  const Mac expected = message_mac(key, channel, bytes, size - kMacBytes);
  return crypto_verify_32(expected.data(), bytes + size - kMacBytes) == 0;
}

}  // namespace hsa::msgs
