// Decoding bytes from the network into an LCM type, safely: the one way hsa does it (hsad's LCM
// bridge for setpoints and commands, hsactl for status and telemetry).
#pragma once

#include <cstddef>
#include <cstring>
#include <exception>
#include <limits>
#include <vector>

namespace hsa::msgs {

// Decodes an LCM message that must be exactly `size` bytes of its type's own encoding: false for
// another type (the fingerprint), a truncated message, bytes after its end (a valid message with
// junk appended is not that message, and the MAC is found by its position at the end), and any
// encoding that the type would not have written itself.
//
// Two flaws of lcm-gen 1.3.1's string decoding make the last two checks necessary (both found by
// tests/fuzz/fuzz_lcm_messages.cpp). It checks a string's length only against the bytes left, so a
// length of 0 or below makes it call std::string::assign with a length of SIZE_MAX, which throws
// std::length_error: one forged datagram would end the LCM thread, and hsad with it. And it takes
// whatever byte stands where the terminating NUL belongs, and keeps NULs inside the text, so
// different bytes decode to the same message. Hence: never throws, and the message must encode
// back to exactly the bytes it came from.
template <typename LcmType>
[[nodiscard]] bool decode_exact(LcmType& msg, const void* data, std::size_t size) noexcept {
  if (data == nullptr || size > static_cast<std::size_t>(std::numeric_limits<int>::max())) return false;
  try {
    if (msg.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return false;
    if (static_cast<std::size_t>(msg.getEncodedSize()) != size) return false;
    std::vector<unsigned char> again(size);
    return msg.encode(again.data(), 0, static_cast<int>(size)) == static_cast<int>(size) &&
           std::memcmp(again.data(), data, size) == 0;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace hsa::msgs
