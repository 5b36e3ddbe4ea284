#include "drivers/gpiod/gpio_lines.hpp"

#include <fcntl.h>
#include <gpiod.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>


namespace hsa::io::gpiod {
namespace {

std::string error_text(int error) { return std::generic_category().message(error); }

std::string chip_text(gpiod_chip* chip) {
  return std::string(gpiod_chip_name(chip)) + " [" + gpiod_chip_label(chip) + "]";
}

// The GPIO chip devices in /dev, sorted: "/dev/gpiochip0", ...
std::vector<std::string> chip_devices() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("gpiochip", 0) == 0) out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

int request_flags(const LineChannel& c) {
  int flags = 0;
  if (c.active_low) flags |= GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW;
  switch (c.bias) {
    case Bias::as_is: break;
    case Bias::disable: flags |= GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE; break;
    case Bias::pull_up: flags |= GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP; break;
    case Bias::pull_down: flags |= GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN; break;
  }
  switch (c.drive) {
    case Drive::push_pull: break;
    case Drive::open_drain: flags |= GPIOD_LINE_REQUEST_FLAG_OPEN_DRAIN; break;
    case Drive::open_source: flags |= GPIOD_LINE_REQUEST_FLAG_OPEN_SOURCE; break;
  }
  return flags;
}

// Why a request failed, in the operator's terms. Called right after the failed request.
std::string request_error(const LineChannel& c, gpiod_line* line, const std::string& what, int error) {
  const std::string head = c.address.line_key + ": " + what;
  if (error == EBUSY) {
    // The kernel knows who holds the line; libgpiod reads it back with the line info.
    const char* consumer = gpiod_line_update(line) == 0 ? gpiod_line_consumer(line) : nullptr;
    return head + " is busy: it is held by consumer '" +
           (consumer != nullptr ? consumer : "(unnamed: the kernel or a driver)") +
           "'. Stop that user of the line (gpioinfo lists every line and its consumer) or pick "
           "another line";
  }
  std::string hint;
  if (error == ENODEV || error == ENXIO) {
    hint = " (this line cannot raise an interrupt, so it cannot report edges: set edge_events = false)";
  } else if (error == EINVAL || error == ENOTTY || error == EOPNOTSUPP) {
    hint = " (the kernel refused the request: bias needs Linux 5.5 or later, open_drain/open_source "
           "need a chip that supports them, and libgpiod 1.6 needs the v1 GPIO character device, "
           "CONFIG_GPIO_CDEV_V1)";
  } else if (error == EACCES || error == EPERM) {
    hint = " (the daemon's user needs read-write access to the chip's /dev/gpiochip* device)";
  }
  return head + " could not be requested: " + error_text(error) + hint;
}

}  // namespace

std::string missing_chip_message(const LineAddress& a, int error) {
  const std::string head = a.chip_key + ": no GPIO chip '" + a.chip + "'";
  const std::vector<std::string> devices = chip_devices();
  if (devices.empty()) {
    return head +
           ": this kernel has no GPIO character device (/dev/gpiochip* does not exist). A machine "
           "with GPIO lines needs the driver of its GPIO controller loaded (for a test without "
           "hardware: the gpio-sim module) and a kernel with CONFIG_GPIO_CDEV_V1, the interface "
           "libgpiod 1.6 uses";
  }
  if (error == EACCES || error == EPERM) {
    return head + ": " + error_text(error) +
           " (the daemon's user needs read-write access to /dev/gpiochip*, e.g. through the group "
           "that owns them)";
  }
  std::string present;
  for (const std::string& device : devices) {
    if (!present.empty()) present += ", ";
    if (gpiod_chip* chip = gpiod_chip_open(device.c_str())) {
      present += chip_text(chip) + " with " + std::to_string(gpiod_chip_num_lines(chip)) + " lines";
      gpiod_chip_close(chip);
    } else {
      present += device + " (cannot open: " + error_text(errno) + ")";
    }
  }
  return head + " (" + error_text(error) +
         "); expected a chip name like \"gpiochip0\", a /dev path, a label or a number. Present: " +
         present;
}

gpiod_chip* GpioLines::open_chip(const LineAddress& a) {
  for (const Chip& c : chips_) {
    if (c.lookup == a.chip) return c.chip;
  }
  errno = 0;
  gpiod_chip* chip = gpiod_chip_open_lookup(a.chip.c_str());
  if (chip == nullptr) throw std::runtime_error(missing_chip_message(a, errno != 0 ? errno : ENOENT));
  chips_.push_back({a.chip, chip});
  return chip;
}

GpioLines::GpioLines(const std::vector<LineChannel>& channels) {
  try {
    // Resolve every line first, so that a wrong name is reported before anything is requested.
    for (std::size_t i = 0; i < channels.size(); ++i) {
      const LineAddress& a = channels[i].address;
      gpiod_chip* chip = open_chip(a);
      gpiod_line* line = nullptr;
      if (a.by_name) {
        errno = 0;
        line = gpiod_chip_find_line(chip, a.name.c_str());
        if (line == nullptr) {
          std::string names;
          int listed = 0;
          const unsigned int count = gpiod_chip_num_lines(chip);
          for (unsigned int o = 0; o < count && listed < 16; ++o) {
            gpiod_line* l = gpiod_chip_get_line(chip, o);
            if (l == nullptr || gpiod_line_name(l) == nullptr) continue;
            names += std::string(listed++ == 0 ? "" : ", ") + "'" + gpiod_line_name(l) + "'";
          }
          throw std::runtime_error(a.line_key + ": no line named '" + a.name + "' on chip " +
                              chip_text(chip) + " (its named lines: " +
                              (names.empty() ? "none" : names) + "; or give the offset as an integer)");
        }
      } else {
        const unsigned int count = gpiod_chip_num_lines(chip);
        if (a.offset >= count) {
          throw std::runtime_error(a.line_key + ": expected an offset below " +
                              std::to_string(count) + " (chip " + chip_text(chip) + " has " +
                              std::to_string(count) + " lines), got " + std::to_string(a.offset));
        }
        line = gpiod_chip_get_line(chip, a.offset);
        if (line == nullptr) {
          throw std::runtime_error(a.line_key + ": cannot read line " + std::to_string(a.offset) +
                              " of chip " + chip_text(chip) + ": " + error_text(errno));
        }
      }
      Line l;
      l.line = line;
      const char* name = gpiod_line_name(line);
      l.description = (name != nullptr ? "line '" + std::string(name) + "' (offset " : "line (offset ") +
                      std::to_string(gpiod_line_offset(line)) + ") of " + chip_text(chip);
      // Two channels on one line: the same chip reached through two spellings, or a line
      // given once by name and once by offset.
      for (std::size_t j = 0; j < lines_.size(); ++j) {
        if (gpiod_line_offset(lines_[j].line) == gpiod_line_offset(line) &&
            std::strcmp(gpiod_chip_name(gpiod_line_get_chip(lines_[j].line)), gpiod_chip_name(chip)) == 0) {
          throw std::runtime_error(a.line_key + ": expected a line no other channel uses, got " +
                                   l.description + ", which is also channels[" + std::to_string(j) + "] (" +
                                   channels[j].info.name + ")");
        }
      }
      lines_.push_back(std::move(l));
    }

    for (std::size_t i = 0; i < channels.size(); ++i) {
      const LineChannel& c = channels[i];
      Line& l = lines_[i];
      gpiod_line_request_config config{};
      config.consumer = consumer_name;
      config.flags = request_flags(c);
      std::string what;
      if (c.info.kind == ChannelKind::digital_output) {
        config.request_type = GPIOD_LINE_REQUEST_DIRECTION_OUTPUT;
        what = l.description + " (output)";
      } else if (c.edge_events) {
        config.request_type = GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES;
        what = l.description + " (input with edge events)";
      } else {
        config.request_type = GPIOD_LINE_REQUEST_DIRECTION_INPUT;
        what = l.description + " (input)";
      }
      errno = 0;
      if (gpiod_line_request(l.line, &config, c.safe_value ? 1 : 0) != 0) {
        throw std::runtime_error(request_error(c, l.line, what, errno));
      }
      if (c.edge_events) {
        l.event_fd = gpiod_line_event_get_fd(l.line);
        const int fl = l.event_fd < 0 ? -1 : fcntl(l.event_fd, F_GETFL);
        if (fl < 0 || fcntl(l.event_fd, F_SETFL, fl | O_NONBLOCK) != 0) {
          throw std::runtime_error(c.address.line_key + ": cannot make the event file of " +
                              l.description + " non-blocking: " + error_text(errno));
        }
      }
    }
  } catch (...) {
    release();
    throw;
  }
}

GpioLines::~GpioLines() { release(); }

void GpioLines::release() {
  // Closing a chip releases its requested lines (and their fds) too.
  for (Chip& c : chips_) gpiod_chip_close(c.chip);
  chips_.clear();
  lines_.clear();
}

int GpioLines::value(std::size_t i) noexcept { return gpiod_line_get_value(lines_[i].line); }

int GpioLines::drain_edges(std::size_t i) noexcept {
  // The kernel's v1 event FIFO holds 16 events: one full read normally empties it. Bounded so a
  // bouncing contact cannot keep the RT thread here.
  gpiod_line_event events[16];
  int total = 0;
  for (int round = 0; round < 4; ++round) {
    const int n = gpiod_line_event_read_fd_multiple(lines_[i].event_fd, events, 16);
    if (n < 0) return errno == EAGAIN ? total : -1;
    total += n;
    if (n < 16) break;
  }
  return total;
}

int GpioLines::set(std::size_t i, bool value) noexcept {
  return gpiod_line_set_value(lines_[i].line, value ? 1 : 0);
}

}  // namespace hsa::io::gpiod
