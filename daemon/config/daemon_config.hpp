// Everything hsad reads from its TOML configuration, validated and in
// SI units. load_config() (load_config.hpp) produces it; describe() (describe.hpp) summarizes it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "daemon/config/axis_config.hpp"
#include "daemon/config/metrics_config.hpp"

namespace hsa::daemon {

inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

struct RealtimeConfig {
  int priority = 80;              // SCHED_FIFO priority, 1–99
  int cpu = -1;                   // CPU to pin the RT thread to; -1 = no affinity
  bool isolate_cpu = true;        // with a cpu: hsad's other threads stay off it (housekeeping_affinity.hpp)
  bool require_realtime = false;  // refuse to start when SCHED_FIFO or mlockall is refused
  std::uint32_t base_period_us = 100;   // the base tick: the valve loop's period
  std::uint32_t stack_prefault_kib = 256;  // RT stack touched before the loop starts

  [[nodiscard]] double base_period_s() const { return base_period_us * 1e-6; }
  [[nodiscard]] double base_rate_hz() const { return 1e6 / base_period_us; }
};

// Who may command the axes (msgs/README.md, Authentication). Keys are read at start: one file
// <key_dir>/<operator>.key per operator, mode 0600, owned by hsad's user.
struct AuthSettings {
  bool require_auth = true;              // false: anyone who reaches lcm_url commands the axes
  std::string key_dir = "/etc/hsa/keys";
  double stamp_window_s = 2.0;           // how far a sender's clock may be from hsad's
  double lease_timeout_s = 30.0;         // an axis's lease ends this long after its holder's last message
  // What every command must name to be obeyed here, and every status says: one per rig, so that a
  // command signed for one rig is refused by another that holds the same key. Default: the host name.
  std::string system_name;
};

// The RT cycle reports the drivers whose read or write failed as one bit each of a 64-bit mask
// (DriverSet::read_all, an axis's driver_mask): at most this many [[drivers]] instances. One
// instance of a bus driver serves every axis whose signals it carries; the `sim` driver is one rig.
inline constexpr std::size_t kMaxDriverInstances = 64;

struct DriverConfig {
  std::string name;    // unique instance name, referred to by signals' `driver`
  std::string plugin;  // "sim" → libhsa_driver_sim.so on the plugin path, or a path with a '/'
  // Handed as is to the plugin's on_configure, which validates its own keys. Moved out of the
  // parsed file, so its nodes keep their source positions and a plugin's message names the line.
  toml::table settings;
};

struct DaemonConfig {
  std::string source;  // the file (or test source name) it was read from
  std::string lcm_url = kDefaultLcmUrl;
  AuthSettings auth;
  RealtimeConfig realtime;
  std::vector<DriverConfig> drivers;  // in file order
  std::vector<AxisConfig> axes;       // in file order, at least one
  RecorderConfig recorder;            // [recorder]: where the flight recorder's captures go
  MetricsConfig metrics;              // [metrics]: the Prometheus textfile, if any
  std::string text;                   // the configuration as read (a capture file holds it)
};

}  // namespace hsa::daemon
