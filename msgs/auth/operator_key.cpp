#include "msgs/auth/operator_key.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace hsa::msgs {

namespace {

constexpr std::size_t kHexDigits = 2 * kKeyBytes;

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw KeyFileError(path + ": " + what); }

std::string errno_text(int err) { return std::strerror(err); }

void init_sodium(const std::string& path) {
  if (sodium_init() < 0) fail(path, "libsodium could not be initialised");
}

std::string mode_text(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

// Owned by this process's user or by root: nobody else can have changed it.
bool trusted_owner(uid_t uid) { return uid == geteuid() || uid == 0; }

// A file descriptor closed on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) close(fd);
  }
};

}  // namespace

bool valid_operator_id(std::string_view id) {
  if (id.empty() || id.size() > 32 || id.front() == '.') return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

OperatorKey read_key_file(const std::string& path) {
  init_sodium(path);
  const std::filesystem::path p(path);
  if (p.extension() != ".key") fail(path, "a key file's name must be <operator>.key");
  OperatorKey out;
  out.operator_id = p.stem().string();
  if (!valid_operator_id(out.operator_id)) {
    fail(path, "the operator id '" + out.operator_id + "' must be 1 to 32 of [A-Za-z0-9_.-], not starting with '.'");
  }

  // O_NOFOLLOW: the checks below must be about the file that is read, not a link to another.
  const Fd file{open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK)};
  if (file.fd < 0) {
    fail(path,
         errno == ELOOP ? "is a symbolic link; a key must be a regular file" : "cannot open: " + errno_text(errno));
  }
  struct stat st {};
  if (fstat(file.fd, &st) != 0) fail(path, "cannot stat: " + errno_text(errno));
  if (!S_ISREG(st.st_mode)) fail(path, "is not a regular file");
  if ((st.st_mode & 077) != 0) {
    fail(path, "mode " + mode_text(st.st_mode) + " lets others read or change the key; it must be 0600 (chmod 600)");
  }
  if (!trusted_owner(st.st_uid)) {
    fail(path, "is owned by uid " + std::to_string(st.st_uid) + ", not by this user (uid " +
                   std::to_string(geteuid()) + ") or root");
  }

  char text[kHexDigits + 2];
  const ssize_t n = read(file.fd, text, sizeof text);
  if (n < 0) fail(path, "cannot read: " + errno_text(errno));
  std::size_t length = static_cast<std::size_t>(n);
  if (length == kHexDigits + 1 && text[kHexDigits] == '\n') --length;
  std::size_t decoded = 0;
  const bool hex = length == kHexDigits &&
                   sodium_hex2bin(out.key.data(), out.key.size(), text, length, nullptr, &decoded, nullptr) == 0 &&
                   decoded == kKeyBytes;
  sodium_memzero(text, sizeof text);
  if (!hex) {
    const std::string found =
        length < kHexDigits ? "is too short: " + std::to_string(length) + " characters, fewer than a " +
                                  std::to_string(kKeyBytes) + "-byte key's; "
                            : "";
    fail(path, found + "a key file must hold exactly " + std::to_string(kHexDigits) +
                   " hexadecimal digits (and an optional newline), as `hsactl keygen` writes");
  }
  if (const std::string_view why = key_weakness(out.key); !why.empty()) {
    sodium_memzero(out.key.data(), out.key.size());
    fail(path, "is a weak key (" + std::string(why) + "); make a new one with `hsactl keygen`");
  }
  return out;
}

std::string_view key_weakness(const Key& key) {
  if (std::all_of(key.begin(), key.end(), [](unsigned char b) { return b == 0; })) return "all zero";
  if (std::all_of(key.begin(), key.end(), [&](unsigned char b) { return b == key.front(); })) {
    return "one byte repeated 32 times";
  }
  return {};
}

std::vector<OperatorKey> read_key_dir(const std::string& dir) {
  struct stat st {};
  if (stat(dir.c_str(), &st) != 0) fail(dir, "cannot open the key folder: " + errno_text(errno));
  if (!S_ISDIR(st.st_mode)) fail(dir, "is not a folder");
  if ((st.st_mode & 022) != 0) {
    fail(dir, "mode " + mode_text(st.st_mode) +
                  " lets others add keys; the key folder must not be writable by group or others");
  }
  if (!trusted_owner(st.st_uid)) {
    fail(dir, "is owned by uid " + std::to_string(st.st_uid) + ", not by this user (uid " +
                  std::to_string(geteuid()) + ") or root");
  }
  std::vector<OperatorKey> keys;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".key") keys.push_back(read_key_file(entry.path().string()));
  }
  if (ec) fail(dir, "cannot list the key folder: " + ec.message());
  if (keys.empty()) fail(dir, "holds no <operator>.key file; make one with `hsactl keygen NAME --dir " + dir + "`");
  std::sort(keys.begin(), keys.end(), [](const auto& a, const auto& b) { return a.operator_id < b.operator_id; });
  return keys;
}

std::string write_new_key(const std::string& dir, std::string_view operator_id) {
  const std::string path = (std::filesystem::path(dir) / (std::string(operator_id) + ".key")).string();
  if (!valid_operator_id(operator_id)) {
    fail(path, "the operator id '" + std::string(operator_id) +
                   "' must be 1 to 32 of [A-Za-z0-9_.-], not starting with '.'");
  }
  init_sodium(path);
  Key key;
  do {
    randombytes_buf(key.data(), key.size());
  } while (!key_weakness(key).empty());  // one chance in 2^248: never hand one out all the same
  char text[kHexDigits + 1];
  sodium_bin2hex(text, sizeof text, key.data(), key.size());
  sodium_memzero(key.data(), key.size());

  // O_EXCL: an existing key (perhaps the one a daemon already trusts) is never replaced.
  const Fd file{open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600)};
  if (file.fd < 0) {
    sodium_memzero(text, sizeof text);
    fail(path, errno == EEXIST ? "exists already; a key is never overwritten" : "cannot create: " + errno_text(errno));
  }
  text[kHexDigits] = '\n';
  const bool written = write(file.fd, text, sizeof text) == static_cast<ssize_t>(sizeof text) && fsync(file.fd) == 0;
  const int err = errno;
  sodium_memzero(text, sizeof text);
  if (!written) {
    unlink(path.c_str());
    fail(path, "cannot write: " + errno_text(err));
  }
  return path;
}

}  // namespace hsa::msgs
