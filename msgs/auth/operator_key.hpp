// An operator's key: 32 random bytes for HMAC-SHA-256, kept in a file `<operator>.key` that holds
// them as 64 hexadecimal digits.
//
// A key file is trusted only when nobody but its owner can read or change it: a regular file (not
// a symbolic link), mode 0600 or stricter, owned by the user who reads it (or by root). The folder
// of a daemon's keys must not be writable by anyone else either, or a stranger could add a key.
// A key must hold all kKeyBytes bytes and must not be weak (all zero, or one byte repeated). Every
// refusal names the file and what is wrong with it.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hsa::msgs {

inline constexpr std::size_t kKeyBytes = 32;
using Key = std::array<unsigned char, kKeyBytes>;

struct OperatorKey {
  std::string operator_id;  // the file's name without ".key"
  Key key{};
};

// A key file or folder that cannot be used, with a message that names it.
class KeyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// 1 to 32 of [A-Za-z0-9_.-], not starting with '.': an operator id is a file name and travels in
// every message.
[[nodiscard]] bool valid_operator_id(std::string_view id);

// Why `key` is too weak to sign with, or "" when it is not: all zero, or one byte repeated (the
// keys a hand-made file or a broken generator produces). read_key_file refuses such a key and
// write_new_key never writes one.
[[nodiscard]] std::string_view key_weakness(const Key& key);

// Reads one key file. Throws KeyFileError; also for a key shorter than kKeyBytes and a weak one.
[[nodiscard]] OperatorKey read_key_file(const std::string& path);

// Reads every `*.key` in `dir` (other files are ignored), sorted by operator id. Throws
// KeyFileError for a folder that is missing, not a folder, writable by group or others, or holds
// no key, and for the first key file that read_key_file refuses.
[[nodiscard]] std::vector<OperatorKey> read_key_dir(const std::string& dir);

// Makes a new random key in `<dir>/<operator_id>.key` with mode 0600 and returns the path. Never
// overwrites: an existing file is an error. Throws KeyFileError (also for an invalid id).
std::string write_new_key(const std::string& dir, std::string_view operator_id);

}  // namespace hsa::msgs
