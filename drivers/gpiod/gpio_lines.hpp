// The GPIO lines of one gpiod driver, requested from the kernel through libgpiod 1.6 (the v1
// GPIO character device), and the few calls the real-time path makes on them.
//
// Construction (on_configure, a normal thread): open each chip once (gpiod_chip_open_lookup:
// name, path, label or number), find each line by name or offset, refuse the same line twice,
// then request every line with the consumer name "hsad": inputs as inputs, or for both edges
// when edge_events is set (their event fd made non-blocking); outputs as outputs already at
// their safe value. Any failure releases what was taken and throws std::runtime_error with a message
// that names the setting key, the chip and the line, and for a busy line the consumer holding it.
//
// The real-time calls (value, drain_edges, set) are one ioctl or one non-blocking read each:
// libgpiod 1.6 does these with stack buffers only, so nothing allocates, locks or blocks.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "drivers/gpiod/gpiod_settings.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace hsa::io::gpiod {

inline constexpr const char* consumer_name = "hsad";

class GpioLines {
 public:
  // Throws std::runtime_error.
  explicit GpioLines(const std::vector<LineChannel>& channels);
  ~GpioLines();  // releases the lines and closes the chips
  GpioLines(const GpioLines&) = delete;
  GpioLines& operator=(const GpioLines&) = delete;

  // Real time, indexed like the channels. The logical value (active-low applied by the
  // kernel): 0 or 1, or -1 when the kernel refused (errno set).
  int value(std::size_t i) noexcept;
  // Edge events queued since the last call (at most 64 per call: the kernel keeps 16), 0 when
  // none, -1 on error. Only for channels with edge_events.
  int drain_edges(std::size_t i) noexcept;
  // Sets an output's logical value; 0 or -1.
  int set(std::size_t i, bool value) noexcept;

  // "line 'hsa-estop' (offset 0) of gpiochip0 [gpio-sim.0-node0]", for messages.
  [[nodiscard]] const std::string& describe(std::size_t i) const { return lines_[i].description; }

 private:
  struct Chip {
    std::string lookup;  // as the settings gave it
    gpiod_chip* chip = nullptr;
  };
  struct Line {
    gpiod_line* line = nullptr;
    int event_fd = -1;
    std::string description;
  };

  gpiod_chip* open_chip(const LineAddress& a);
  void release();

  std::vector<Chip> chips_;
  std::vector<Line> lines_;
};

// The message for a chip that cannot be opened: which key, and what exists instead. On a
// machine without any /dev/gpiochip* it says that the kernel has no GPIO character device.
// `error` is the errno of the failed open.
std::string missing_chip_message(const LineAddress& a, int error);

}  // namespace hsa::io::gpiod
