// Shared by the modbus plugin's end-to-end tests: the settings text they configure the plugin
// with, and the plugin loaded and cycled the way hsad does it.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "drivers/clock.hpp"
#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/test_modbus_support.hpp"

namespace hsa::io::modbus_test {

// A TCP link to a peer on 127.0.0.1:port, polled every 2 ms, samples stale after 0.1 s, with the
// given response timeout and reconnect back-off (0.05 s up to reconnect_max_s).
inline std::string tcp_link(int port, double response_timeout_s, double reconnect_max_s) {
  return "transport = \"tcp\"\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) +
         "\npoll_period_s = 0.002\nresponse_timeout_s = " + std::to_string(response_timeout_s) +
         "\nmax_age_s = 0.1\nreconnect_min_s = 0.05\nreconnect_max_s = " + std::to_string(reconnect_max_s) + "\n";
}

// One [[channels]] entry; `more` adds its other keys (type, word_order, scale, safe_value, ...).
inline std::string channel(const std::string& name, const std::string& kind, const std::string& table, int address,
                           const std::string& more = "") {
  return "[[channels]]\nname = \"" + name + "\"\nkind = \"" + kind + "\"\ntable = \"" + table +
         "\"\naddress = " + std::to_string(address) + "\n" + more;
}

// The plugin from HSA_PLUGIN_DIR and the RT loop hsad runs around it: read, then write while
// active. As in hsad, the cycle's time `t` is CLOCK_MONOTONIC less an epoch taken at the start,
// so the plugin's samples (stamped on CLOCK_MONOTONIC by its bus thread) land on the same clock.
struct DriverLoop {
  static constexpr Duration cycle_period = std::chrono::milliseconds(1);

  explicit DriverLoop(const std::string& settings)
      : driver(PluginLoader({HSA_PLUGIN_DIR}).load_driver("io", "modbus", toml::parse(settings))) {}

  // The time a cycle starting now has.
  [[nodiscard]] Timestamp now() const { return Timestamp{monotonic_ns() - epoch_ns}; }

  void cycle() {
    t = now();
    ASSERT_EQ(driver->read(t, cycle_period), IoStatus::ok);
    if (driver->state() == DriverState::active) {
      ASSERT_EQ(driver->write(t, cycle_period), IoStatus::ok);
    }
  }
  ChannelSlot& slot(const std::string& name) { return driver->slots()[*driver->find_channel(name)]; }
  // Runs cycles (with `check` after each) until `condition` holds, at most `timeout`.
  bool run_until(const std::function<bool()>& condition, std::chrono::milliseconds timeout,
                 const std::function<void()>& check = {}) {
    return wait_until(condition, timeout, [&] {
      cycle();
      if (check) check();
    });
  }

  std::unique_ptr<DriverHandle> driver;
  std::int64_t epoch_ns = monotonic_ns();
  Timestamp t{};  // the last cycle's
};

}  // namespace hsa::io::modbus_test
