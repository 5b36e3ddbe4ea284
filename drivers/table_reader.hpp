// Typed, located access to one TOML table: the configuration's one reader, used by the daemon for
// its own file and by every plugin for its settings table. Every error it throws is a ConfigError
// of the form
//   <file>:<line>:<column>: <key path>: expected <what>, got <value>
// located at the offending value, or at the table when a required key is missing. The key path
// is the table's own path ("axes[0].pi") joined with the key, so nested errors read as the user
// would write them. A plugin reads its settings table from its own root (`of`), so its key paths
// start inside the table ("channels[2].address"); the daemon names the driver around them.
//
// Unknown keys are errors too (reject_unknown_keys): a misspelt key that silently falls back to a
// default is how a rig ends up with the wrong valve. This header includes toml++; only
// configuration code needs it, never the real-time path.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "control/setting_range.hpp"
#include "drivers/clock.hpp"
#include "drivers/config_error.hpp"

namespace hsa::io {

// `text` parsed as TOML; a syntax error is a ConfigError "<source_name>:<line>:<column>: TOML
// syntax error: …", as every other configuration error reads.
[[nodiscard]] toml::table parse_toml(std::string_view text, std::string_view source_name);

// The configuration's one range type, shared with the control laws' settings.
using NumberRange = control::SettingRange;
using control::format_setting;


class TableReader {
 public:
  // The document's root table; `source_name` is the file name that starts every message.
  static TableReader root(const toml::table& table, std::string_view source_name);
  // A table read from its own root, named in messages by the file it was parsed from (its source
  // path) when it has one: a plugin's settings table.
  static TableReader of(const toml::table& table);

  [[nodiscard]] const toml::table& table() const { return *table_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::string key_path(std::string_view key) const;
  [[nodiscard]] bool has(std::string_view key) const { return table_->contains(key); }

  // Each getter returns `fallback` when the key is absent, and fails when it is absent without a
  // fallback (a required key) or has the wrong type or value.
  [[nodiscard]] double number(std::string_view key, const NumberRange& range,
                              std::optional<double> fallback = std::nullopt) const;
  [[nodiscard]] std::int64_t integer(std::string_view key, std::int64_t min, std::int64_t max,
                                     std::optional<std::int64_t> fallback = std::nullopt) const;
  // A number of seconds in `range`, rounded to nanoseconds; fails when it rounds to less than 1 µs.
  [[nodiscard]] Duration duration(std::string_view key, const NumberRange& range,
                                  std::optional<double> fallback_s = std::nullopt) const;
  [[nodiscard]] bool boolean(std::string_view key, std::optional<bool> fallback = std::nullopt) const;
  // `expected` words what the string must be, for the type error ("a plugin name or path").
  [[nodiscard]] std::string string(std::string_view key, std::string_view expected,
                                   std::optional<std::string_view> fallback = std::nullopt) const;
  [[nodiscard]] std::string choice(std::string_view key,
                                   std::initializer_list<std::string_view> allowed,
                                   std::optional<std::string_view> fallback = std::nullopt) const;

  // A sub-table: nullopt when absent and not required.
  [[nodiscard]] std::optional<TableReader> table(std::string_view key, bool required,
                                                 std::string_view expected) const;
  // An array of tables ([[key]]), each read with the path "key[i]"; empty when absent.
  [[nodiscard]] std::vector<TableReader> tables(std::string_view key) const;

  // Fails at the first key not in `known`, listing the known ones: typos must not pass silently.
  void reject_unknown_keys(std::initializer_list<std::string_view> known) const;
  void reject_unknown_keys(std::span<const std::string_view> known) const;

  // "<key path>: expected <expected>, got <value>" at the key's value, or "<key path>: required
  // key is missing, expected <expected>" at this table when the key is absent.
  [[noreturn]] void fail(std::string_view key, std::string_view expected) const;
  // "<this table's path>: <message>" at this table.
  [[noreturn]] void fail_here(std::string_view message) const;

 private:
  TableReader(const toml::table& table, std::string path, std::shared_ptr<const std::string> source,
              toml::source_position fallback);

  [[nodiscard]] TableReader child(const toml::table& table, std::string path) const;
  [[nodiscard]] toml::source_position position_of(const toml::node* node) const;
  [[noreturn]] void throw_at(toml::source_position where, std::string_view key_path,
                             std::string_view message) const;

  const toml::table* table_;
  std::string path_;
  std::shared_ptr<const std::string> source_;
  toml::source_position where_;  // this table's position, or its parent's when it has none
};

}  // namespace hsa::io
