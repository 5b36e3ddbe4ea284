// Typed access to a driver's TOML settings, with errors that name the key and what was expected:
//   key 'valve' must be "servo" or "proportional", got "foo"
//
// Drivers read their settings through this in on_configure, catch SettingsError and return its
// message as the failure. Unknown keys are errors too (reject_unknown_keys), because a
// misspelt key that silently falls back to a default is how a rig ends up with the wrong valve.
// This header includes toml++; only configuration code needs it, never the real-time path.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>

#include <toml++/toml.h>

#include "drivers/clock.hpp"

namespace hsa::io {

class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Settings {
 public:
  // `path` prefixes key names in messages, for nested tables: "events[2]." gives
  // "key 'events[2].at_s' ...".
  explicit Settings(const toml::table& table, std::string path = {});

  [[nodiscard]] bool has(std::string_view key) const { return table_.contains(key); }
  [[nodiscard]] const toml::table& table() const { return table_; }
  [[nodiscard]] std::string key_name(std::string_view key) const;

  // Each returns `fallback` when the key is absent and throws SettingsError when it has the
  // wrong type or value. number() accepts integers and floats.
  [[nodiscard]] double number(std::string_view key, double fallback) const;
  [[nodiscard]] double positive_number(std::string_view key, double fallback) const;
  [[nodiscard]] std::int64_t integer(std::string_view key, std::int64_t fallback) const;
  // An integer in [low, high].
  [[nodiscard]] int integer_in(std::string_view key, std::int64_t fallback, std::int64_t low,
                               std::int64_t high) const;
  // A positive number of seconds, rounded to nanoseconds; at least 1 µs.
  [[nodiscard]] Duration duration(std::string_view key, double fallback_s) const;
  [[nodiscard]] bool boolean(std::string_view key, bool fallback) const;
  [[nodiscard]] std::string string(std::string_view key, std::string_view fallback) const;
  // A string that must be one of `allowed`.
  [[nodiscard]] std::string choice(std::string_view key,
                                   std::initializer_list<std::string_view> allowed,
                                   std::string_view fallback) const;

  void reject_unknown_keys(std::initializer_list<std::string_view> known) const;

  [[noreturn]] void fail(std::string_view key, const std::string& expected) const;

 private:
  const toml::table& table_;
  std::string path_;
};

}  // namespace hsa::io
