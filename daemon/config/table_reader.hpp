// Typed, located access to one TOML table of the configuration. Every error it throws is a
// ConfigError of the form
//   <file>:<line>:<column>: <key path>: expected <what>, got <value>
// located at the offending value, or at the table when a required key is missing. The key path
// is the table's own path ("axes[0].pi") joined with the key, so nested errors read as the user
// would write them.
//
// Compared with io::Settings (the plugins' reader) this adds line numbers and key paths through
// nested tables and arrays, which the daemon's own file needs and a plugin's small table does not.
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

#include "control/law_settings.hpp"

namespace hsa::daemon {

// The configuration's one range type (control::SettingRange), under the name this reader's callers
// use.
using NumberRange = control::SettingRange;
using control::format_setting;


class TableReader {
 public:
  // The document's root table; `source_name` is the file name that starts every message.
  static TableReader root(const toml::table& table, std::string_view source_name);

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

}  // namespace hsa::daemon
