// Keys and MACs as the msgs/auth tests write them: a key of counting bytes, a MAC in hexadecimal
// (as Python's hmac module prints the reference values).
#pragma once

#include <string>

#include "msgs/auth/message_mac.hpp"

namespace hsa::msgs {

// first, first + 1, ..., first + 31.
inline Key key_of(unsigned char first) {
  Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<unsigned char>(first + i);
  return k;
}

inline std::string hex(const Mac& mac) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const unsigned char b : mac) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

}  // namespace hsa::msgs
