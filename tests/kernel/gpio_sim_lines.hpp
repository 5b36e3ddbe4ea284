// The other end of a gpio-sim chip's lines, for the real-kernel tests: gpio-sim's sysfs files
// drive an input's pull and show what an output is driven to, as a board would see it.
//
//   HSA_GPIO_SIM_SYSFS  the directory holding sim_gpio0 .. sim_gpio7 (tests/kernel/vm-init.sh),
//                       each with `pull` and `value`
//
// Plain POSIX I/O: one write(2) per pull change, so the caller knows the kernel applied it when
// the call returns; one read(2) per value.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace hsa::test::gpio_sim {

inline std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

inline std::string sim_file(int line, const char* file) {
  return env("HSA_GPIO_SIM_SYSFS") + "/sim_gpio" + std::to_string(line) + "/" + file;
}

inline void write_sysfs(const std::string& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0) << "cannot open " << path;
  const ssize_t n = ::write(fd, text.data(), text.size());
  ::close(fd);
  ASSERT_EQ(n, static_cast<ssize_t>(text.size())) << "cannot write '" << text << "' to " << path;
}

// Drives an input line from outside: pulled up (1) or down (0).
inline void pull(int line, bool up) { write_sysfs(sim_file(line, "pull"), up ? "pull-up" : "pull-down"); }

// What gpio-sim says the line is at: for an output, what the requester drives; -1 on error.
inline int sim_value(int line) {
  const std::string path = sim_file(line, "value");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -1;
  char c = '?';
  const ssize_t n = ::read(fd, &c, 1);
  ::close(fd);
  return n == 1 && (c == '0' || c == '1') ? c - '0' : -1;
}

}  // namespace hsa::test::gpio_sim
