// Reads and validates hsad's TOML configuration. The example files in systemd/ document every key.
#pragma once

#include <filesystem>
#include <string_view>

#include "drivers/config_error.hpp"
#include "daemon/config/daemon_config.hpp"

namespace hsa::daemon {

// Throws io::ConfigError naming the file, line and column, key path and what was expected, for a
// file that cannot be read, a TOML syntax error, a wrong type or value, an unknown key, a missing
// required key, a duplicate name, a reference to an unknown driver or a rate that does not divide
// the base rate.
DaemonConfig load_config(const std::filesystem::path& file);

// The same for text in memory; `source_name` stands for the file name in messages.
DaemonConfig parse_config(std::string_view text, std::string_view source_name);

}  // namespace hsa::daemon
